//! Helpers shared by the benchmarks.

use std::path::{Path, PathBuf};

/// A file of `scenarios/`: relative to the working directory (cargo runs benches in the package
/// root) so that a built benchmark also runs from a copy of the repository elsewhere, else in
/// the source tree it was built from.
pub fn scenario_path(name: &str) -> PathBuf {
    let rel = Path::new("scenarios").join(name);
    if rel.exists() {
        rel
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
    }
}
