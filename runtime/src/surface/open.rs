//! [`Surface::read`]: a surface file by its extension — a contact.engineering container
//! (`.zip`, module `container`) or one of the single-topography files (module `read`).

use std::path::Path;

use super::read::{FileKind, ReadOptions};
use super::{Surface, SurfaceError};

impl Surface {
    /// Reads a height map by extension: `.x3p` (feature `x3p`; pixel sizes, offsets
    /// and metres from the file), SurfaceTopography's `.nc` (feature `netcdf`; physical
    /// sizes, unit and periodic flag from the file when it gives them: a file flagged
    /// periodic is read as periodic, and then not detrended), a contact.engineering
    /// container's first topography (`.zip`, feature `container`; another one with
    /// `container::read_container`), `.npy` (feature `npy`) or a
    /// text matrix, both in `height_unit` with the given spacing. Then checks (or repairs) invalid points
    /// and spikes, and removes the form `detrend` (refused on a periodic sample). What
    /// was done is in [`Surface::log`] and [`Surface::form`], a form that dominates the
    /// heights is in [`Surface::warnings`] (module `form`); errors name the file (and
    /// the grid index or field).
    pub fn read(path: &Path, opts: &ReadOptions) -> Result<Surface, SurfaceError> {
        if FileKind::of(path) == FileKind::Container {
            return read_container_first(path, opts);
        }
        Surface::read_file(path, opts)
    }
}

/// A container's first topography.
#[cfg(feature = "container")]
fn read_container_first(path: &Path, opts: &ReadOptions) -> Result<Surface, SurfaceError> {
    super::container::read_container(path, &super::container::Pick::Index(0), opts)
}

#[cfg(not(feature = "container"))]
fn read_container_first(path: &Path, _: &ReadOptions) -> Result<Surface, SurfaceError> {
    Err(SurfaceError::Unsupported(format!(
        "{}: contact.engineering containers (.zip) need the runtime feature `container`",
        path.display()
    )))
}
