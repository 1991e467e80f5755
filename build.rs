//! Sets `cfg(shared_data)` when the project's reference material (`../shared`) sits beside the
//! crate, so tests that read it run there and are reported as *ignored* (not passed) elsewhere:
//! `#[cfg_attr(not(shared_data), ignore = "needs ../shared")]`.

fn main() {
    println!("cargo::rustc-check-cfg=cfg(shared_data)");
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared");
    println!("cargo::rerun-if-changed={}", dir.display());
    if dir.join("README.md").is_file() {
        println!("cargo::rustc-cfg=shared_data");
    }
}
