//! Sets `cfg(shared_data)` when the project's reference material (`../shared`) sits beside the
//! crate, so tests that read it run there and are reported as *ignored* (not passed) elsewhere:
//! `#[cfg_attr(not(shared_data), ignore = "needs ../shared")]`. `FEEDOPT_IGNORE_SHARED=1` at
//! build time acts as if it were absent (to check what a bare clone reports).

fn main() {
    println!("cargo::rustc-check-cfg=cfg(shared_data)");
    // The manifest's folder as cargo gives it when the script runs, not as it was when the
    // script was compiled (`env!`): a build script compiled for a clone elsewhere that shares
    // the target folder looked for that clone's `../shared`, and this checkout's release tests
    // then reported the shared-data tests as ignored.
    let manifest = std::env::var_os("CARGO_MANIFEST_DIR").unwrap_or_default();
    let dir = std::path::Path::new(&manifest).join("../shared");
    println!("cargo::rerun-if-changed={}", dir.display());
    println!("cargo::rerun-if-env-changed=FEEDOPT_IGNORE_SHARED");
    let ignore = std::env::var_os("FEEDOPT_IGNORE_SHARED").is_some_and(|v| v != "0");
    if dir.join("README.md").is_file() && !ignore {
        println!("cargo::rustc-cfg=shared_data");
    }
}
