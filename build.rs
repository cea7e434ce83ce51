//! Links the C++ runtime for the block encoders (feature `encode`):
//! `intel_tex_2` ships Intel's ISPC kernels as prebuilt static libraries,
//! one of which is C++ and needs `libstdc++` (`libc++` on macOS), which
//! the crate does not link itself.

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if std::env::var_os("CARGO_FEATURE_ENCODE").is_none() {
        return;
    }
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    match os.as_str() {
        "macos" | "ios" | "freebsd" => println!("cargo:rustc-link-lib=c++"),
        "windows" => {}
        _ => println!("cargo:rustc-link-lib=stdc++"),
    }
}
