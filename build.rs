//! Build script: records the git commit the binary is built from, for the
//! results' `manifest.json` (`PLYSCAPE_GIT_COMMIT`: the commit hash, with
//! `-dirty` when tracked files differ from it, or `unknown` outside a git
//! checkout or without git).
//!
//! It asks cargo to rerun it only when the answer can change, and names
//! only paths that exist: cargo treats a missing `rerun-if-changed` path as
//! changed on every build, which would rebuild the crate each time (a clone
//! without `.git/packed-refs`, say). Watched: the checkout's `HEAD` and
//! `index`; the branch HEAD points to, as its loose ref file when there is
//! one, else `packed-refs` and the folder the loose file would appear in;
//! the sources. Git is run with `--no-optional-locks` so that `git status`
//! does not rewrite the index it is watching.

use std::path::{Path, PathBuf};
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git")
        .arg("--no-optional-locks")
        .args(args)
        .output()
        .ok()?;
    out.status
        .success()
        .then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

/// The git files whose change can change the commit or its dirty flag.
fn git_inputs() -> Vec<PathBuf> {
    let (Some(dir), Some(common)) = (
        git(&["rev-parse", "--git-dir"]),
        git(&["rev-parse", "--git-common-dir"]),
    ) else {
        return Vec::new();
    };
    let (dir, common) = (PathBuf::from(dir), PathBuf::from(common));
    let mut paths = vec![dir.join("HEAD"), dir.join("index")];
    // The branch HEAD points to (none when HEAD is detached: the commit is
    // in HEAD itself).
    if let Some(branch) = git(&["symbolic-ref", "-q", "HEAD"]).filter(|b| !b.is_empty()) {
        let loose = common.join(&branch);
        if loose.is_file() {
            paths.push(loose);
        } else {
            // Packed: a commit writes a loose file next to its siblings.
            paths.push(common.join("packed-refs"));
            paths.extend(loose.parent().map(Path::to_path_buf));
        }
    }
    // Repositories in the reftable format keep every ref there.
    paths.push(common.join("reftable"));
    paths
}

fn main() {
    let commit = match git(&["rev-parse", "HEAD"]) {
        Some(c) if !c.is_empty() => {
            let dirty = git(&["status", "--porcelain", "--untracked-files=no"])
                .is_some_and(|s| !s.is_empty());
            if dirty {
                format!("{c}-dirty")
            } else {
                c
            }
        }
        _ => "unknown".to_string(),
    };
    println!("cargo:rustc-env=PLYSCAPE_GIT_COMMIT={commit}");
    let sources = ["src", "studies", "Cargo.toml", "Cargo.lock", "build.rs"].map(PathBuf::from);
    let mut seen = Vec::new();
    for path in git_inputs().into_iter().chain(sources) {
        if path.exists() && !seen.contains(&path) {
            println!("cargo:rerun-if-changed={}", path.display());
            seen.push(path);
        }
    }
}
