//! Build script: checks that `tools/setup` has installed MuJoCo and adds an rpath
//! to it, so `cargo run`, `cargo test` and the built binary find libmujoco without
//! `LD_LIBRARY_PATH`.

use std::path::PathBuf;

fn main() {
    println!("cargo::rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    println!("cargo::rerun-if-changed=build.rs");
    let Some(dir) = std::env::var_os("MUJOCO_DYNAMIC_LINK_DIR") else {
        println!(
            "cargo::error=MUJOCO_DYNAMIC_LINK_DIR is not set; run `tools/setup` from the repository root (see README)"
        );
        return;
    };
    let dir = PathBuf::from(dir);
    if !dir.join("libmujoco.so").is_file() {
        println!(
            "cargo::error=MuJoCo is not installed at {}: run `tools/setup` from the repository root (see README)",
            dir.display()
        );
        return;
    }
    // All targets: the binary, tests, benches, examples and doctests.
    println!("cargo::rustc-link-arg=-Wl,-rpath,{}", dir.display());
}
