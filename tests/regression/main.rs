//! Regression tests named after the finding they pin: one module per
//! finding (an issue's defect or a fuzzer's crash), each with the file or
//! input that showed it, made in the test.

mod dds_headers_pillow_read_as_black;
