//! The front ends are cargo features (`cli`, `plot`, `progress`, on by default): the library
//! alone, `cargo build --no-default-features --lib`, links neither clap, plotters, indicatif
//! nor the log subscriber. Checked on the dependency graph cargo resolves for that build
//! (`cargo tree`, offline: no download, no build).

use std::process::Command;

/// The normal (not dev, not build) dependencies of the crate with `features`, one crate name
/// per line.
fn normal_dependencies(features: &[&str]) -> Vec<String> {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let manifest = concat!(env!("CARGO_MANIFEST_DIR"), "/Cargo.toml");
    let out = Command::new(cargo)
        .args(["tree", "--offline", "-e", "normal", "--prefix", "none"])
        .args(["--format", "{p}", "--manifest-path", manifest])
        .args(features)
        .output()
        .expect("cargo runs");
    assert!(
        out.status.success(),
        "cargo tree failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .collect()
}

const FRONT_ENDS: [&str; 4] = ["clap", "plotters", "indicatif", "tracing-subscriber"];

#[test]
fn the_library_alone_pulls_in_no_front_end() {
    let deps = normal_dependencies(&["--no-default-features"]);
    // The listing is real: the solver and the crate itself are in it.
    for needed in ["feedopt", "clarabel", "nalgebra", "serde", "tracing"] {
        assert!(
            deps.iter().any(|d| d == needed),
            "{needed} missing: {deps:?}"
        );
    }
    for front in FRONT_ENDS {
        assert!(
            !deps.iter().any(|d| d == front),
            "{front} in the library build"
        );
    }
}

#[test]
fn the_default_build_has_every_front_end() {
    let deps = normal_dependencies(&[]);
    for front in FRONT_ENDS {
        assert!(deps.iter().any(|d| d == front), "{front} missing: {deps:?}");
    }
}

#[test]
fn each_front_end_is_its_own_feature() {
    for (feature, dep) in [
        ("cli", "clap"),
        ("plot", "plotters"),
        ("progress", "indicatif"),
    ] {
        let deps = normal_dependencies(&["--no-default-features", "--features", feature]);
        for front in ["clap", "plotters", "indicatif"] {
            assert_eq!(
                deps.iter().any(|d| d == front),
                front == dep,
                "--features {feature}: {front}"
            );
        }
    }
}
