//! Records the git commit the extension is built from as `PREBO_GIT_COMMIT` (`_core.GIT_COMMIT`,
//! the provenance of installed copies: python/prebo/provenance.py); empty outside a checkout.

use std::process::Command;

/// The trimmed standard output of `git ARGS` in this crate's folder, if git ran and succeeded.
fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    out.status.success().then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    let commit = git(&["rev-parse", "HEAD"]).unwrap_or_default();
    println!("cargo:rustc-env=PREBO_GIT_COMMIT={commit}");
    // built again when HEAD moves (a commit, a checkout)
    if let Some(dir) = git(&["rev-parse", "--absolute-git-dir"]) {
        println!("cargo:rerun-if-changed={dir}/HEAD");
        println!("cargo:rerun-if-changed={dir}/logs/HEAD");
    }
    println!("cargo:rerun-if-changed=build.rs");
}
