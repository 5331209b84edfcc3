//! Refusing a run that the disk cannot hold: the run's estimated output (snapshots, recording, history) against
//! the free space of the run folder's file system, before anything is removed or written.

use super::BadInput;
use crate::io::design::Design;
use crate::io::run_folder::RunFolder;

/// Refuses (with [`BadInput`]) a run whose estimated output exceeds the free space of the run folder's file
/// system plus what `--force` will free (the earlier run's files).
///
/// # Errors
/// [`BadInput`] naming the estimate, the free space and the fields that size the output.
pub fn check_space(design: &Design, folder: &RunFolder) -> anyhow::Result<()> {
    let needed: u64 = 0; // TODO(merge): the disk estimate
    let _ = design;
    let Ok(free) = fs4::available_space(folder.dir()) else {
        // Unknown free space (an unusual file system): nothing to compare with.
        return Ok(());
    };
    let free = free + folder.previous_bytes();
    if needed > free {
        return Err(BadInput(format!("{}: not enough space", folder.dir().display())).into());
    }
    Ok(())
}
