//! `stentkit mesh`: the reference shape as a closed tube surface (PLACEHOLDER until the tube branch lands).

use std::path::Path;

/// Writes the reference shape of the design to `output`.
pub fn run(design: &Path, output: &Path, segments: usize, samples: usize) -> anyhow::Result<()> {
    anyhow::bail!(
        "not yet: {} {} {segments} {samples}",
        design.display(),
        output.display()
    )
}
