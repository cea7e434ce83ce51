//! Regression tests named after the finding they pin: one module per
//! finding (an issue's defect or a fuzzer's crash), each with the file or
//! input that showed it, made in the test.

mod util;

mod alpha_coverage_bound_broken_by_8bit_rounding;
mod batch_ergonomics;
mod bc_quality_steps_identical;
mod colour_assumption_silent_and_no_color_for_sampling;
mod compress_batch_hangs;
mod dds_headers_pillow_read_as_black;
mod decode_errors_in_debug_words;
mod eight_bit_chains_drift;
mod exif_orientation_ignored;
mod exr_bytes_differ_between_runs;
mod exr_channel_names_lost;
mod exr_data_window_offset_dropped;
mod exr_display_window_unbounded;
mod exr_environment_maps_flattened;
mod float_tiff_one_two_channels_refused;
mod hdr_clipping_unreported;
mod info_json_silent_on_failure;
mod ktx2_bc3_srgb_dfd_fails_ktx_validate;
mod ktx2_dds_errors_give_numbers_not_names;
mod ktx2_dfd_block_dimension_255_panicked;
mod ktx2_orientation_up_ignored;
mod ktx2_supercompressed_levels_bypassed_max_alloc;
mod ktx2_two_channel_read_as_grey_alpha;
mod level_template_ignores_extension;
mod maketx_tx_read_as_one_level;
mod multipart_and_multipage_silently_first;
mod normal_maps_filtered_as_encoded_codes;
mod pillow_bc1_dds_refused;
mod planar_tiff_refused;
mod png_1bit_trns_alpha_ignored;
mod png_colour_chunks_ignored;
mod png_imagemagick_exif_ignored;
mod premultiplied_exr_written_premultiplied_to_png;
mod readme_said_built_fuzz_targets_were_missing;
mod roughness_map_ringing_went_below_zero;
mod rounding_up_writes_invalid_ktx2;
mod sample_ignores_recorded_wrap_modes;
mod sampler_storage_widened;
mod sat_rect_end_just_below_zero_read_a_texel_off;
mod subcommand_long_help_hidden;
mod tiff_associated_alpha_premultiplied_twice;
mod tiff_rgb_data_sample_dropped;
mod tiff_untagged_and_looping_refused;
