//! Writing what a command produces without destroying anything of the user's.
//!
//! - An output that is one of the command's inputs (the same file, however it is spelt: the
//!   same device and inode, or the same canonical path) is refused before any work is done.
//! - An output that is not a regular file (a terminal, a FIFO, `/dev/null`, `/dev/stdout`) is
//!   opened and written into, never replaced: renaming over it would put a regular file where
//!   the device or pipe was.
//! - A regular file is written beside its destination and renamed over it only when complete,
//!   so a failed write (a full disk, Ctrl-C) never leaves half a file or destroys the one that
//!   was there; an existing file keeps its permissions, and a symbolic link stays a link (its
//!   target is replaced).
//! - Standard output (`-`) that is closed, full or a pipe whose reader has gone is an error
//!   with a message, never a panic and never a silent success.

use std::fs::{File, OpenOptions};
use std::io::Write;
use std::path::{Path, PathBuf};

use crate::stdio::is_standard;

/// Refuses `output` when it is one of `inputs` (standard streams excepted): the command would
/// read a file and then replace it with its own output.
pub fn refuse_overwriting_inputs<'a>(
    output: &Path,
    inputs: impl IntoIterator<Item = &'a Path>,
) -> Result<(), String> {
    if is_standard(output) {
        return Ok(());
    }
    for input in inputs.into_iter().filter(|input| !is_standard(input)) {
        if same_file(input, output) {
            return Err(format!(
                "{}: the output is the input {}; write to another file (nothing was written)",
                output.display(),
                input.display()
            ));
        }
    }
    Ok(())
}

/// Whether two paths name one file: the same device and inode where the platform tells,
/// else the same canonical path. A path that does not exist names no existing file.
fn same_file(a: &Path, b: &Path) -> bool {
    let (Ok(ma), Ok(mb)) = (std::fs::metadata(a), std::fs::metadata(b)) else {
        return false;
    };
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        if ma.dev() == mb.dev() && ma.ino() == mb.ino() {
            return true;
        }
    }
    let _ = (ma, mb);
    matches!(
        (std::fs::canonicalize(a), std::fs::canonicalize(b)),
        (Ok(ca), Ok(cb)) if ca == cb
    )
}

/// Writes `bytes` to `path`, or to standard output for `-` (see the module notes).
pub fn write_output(path: &Path, bytes: &[u8]) -> Result<(), String> {
    if is_standard(path) {
        return write_standard_output(bytes);
    }
    match std::fs::metadata(path) {
        // A device, FIFO or socket (also behind a link): written into, never replaced.
        Ok(meta) if !meta.is_file() && !meta.is_dir() => write_into(path, bytes),
        Ok(meta) if meta.is_dir() => Err(format!("{}: is a directory", path.display())),
        // The streams of this process under their /dev and /proc names: written into, so the
        // shell's redirection gets the bytes and no link is replaced.
        Ok(_) if names_own_stream(path) => write_into(path, bytes),
        Ok(meta) => replace_whole(&link_target(path), bytes, Some(meta.permissions())),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            replace_whole(&link_target(path), bytes, None)
        }
        Err(e) => Err(format!("{}: {e}", path.display())),
    }
}

/// `/dev/stdout`, `/dev/stderr`, `/dev/fd/N`, `/proc/self/fd/N`.
fn names_own_stream(path: &Path) -> bool {
    let text = path.to_string_lossy();
    ["/dev/stdout", "/dev/stderr"].contains(&text.as_ref())
        || text.starts_with("/dev/fd/")
        || text.starts_with("/proc/self/fd/")
}

/// Where a symbolic link points (followed to the end), so the link itself is kept; `path`
/// itself when it is no link or the target cannot be resolved (a dangling link's target is
/// created as its own path would be).
fn link_target(path: &Path) -> PathBuf {
    let is_link = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink());
    if !is_link {
        return path.to_path_buf();
    }
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

/// Opens an existing non-regular file for writing (no truncation, no replacement) and writes.
fn write_into(path: &Path, bytes: &[u8]) -> Result<(), String> {
    let mut file = OpenOptions::new()
        .write(true)
        .open(path)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    file.write_all(bytes)
        .and_then(|()| file.flush())
        .map_err(|e| format!("{}: {e} (the output is incomplete)", path.display()))
}

/// Writes a regular file whole: into a new file beside it, synced, then renamed over it.
fn replace_whole(
    path: &Path,
    bytes: &[u8],
    permissions: Option<std::fs::Permissions>,
) -> Result<(), String> {
    let name = path
        .file_name()
        .ok_or_else(|| format!("{}: not a file name", path.display()))?;
    let mut partial = name.to_os_string();
    partial.push(format!(".cutroute-{}.part", std::process::id()));
    let partial = path.with_file_name(partial);
    let written = (|| -> std::io::Result<()> {
        let mut file = OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&partial)?;
        file.write_all(bytes)?;
        if let Some(permissions) = permissions {
            file.set_permissions(permissions)?;
        }
        file.sync_all()?;
        drop(file);
        std::fs::rename(&partial, path)
    })();
    written.map_err(|e| {
        let _ = std::fs::remove_file(&partial);
        format!("{}: {e} (nothing was written)", path.display())
    })
}

/// Standard output, written through its own descriptor: Rust's `stdout()` takes a closed
/// descriptor for a sink that swallows everything, which would report success for output that
/// went nowhere.
fn write_standard_output(bytes: &[u8]) -> Result<(), String> {
    let failed = |e: std::io::Error| {
        let why = match e.kind() {
            std::io::ErrorKind::BrokenPipe => {
                "the reader closed the pipe before the output was written".to_string()
            }
            _ if e.raw_os_error() == Some(EBADF) => "it is closed".to_string(),
            _ => e.to_string(),
        };
        format!("standard output: {why} (the output is incomplete)")
    };
    if standard_output_was_closed() {
        return Err(failed(std::io::Error::from_raw_os_error(EBADF)));
    }
    let mut out = standard_output_file().map_err(failed)?;
    out.write_all(bytes)
        .and_then(|()| out.flush())
        .map_err(failed)
}

/// The errno of a closed descriptor on the platforms that have descriptors.
const EBADF: i32 = 9;

/// Whether descriptor 1 was closed when the program started. Rust's start-up code opens
/// `/dev/null` read-write on a closed standard descriptor, so the output would vanish without
/// an error; a shell's `> /dev/null` opens it write-only, which stays a wanted sink.
#[cfg(target_os = "linux")]
fn standard_output_was_closed() -> bool {
    let null = std::fs::read_link("/proc/self/fd/1").is_ok_and(|p| p == Path::new("/dev/null"));
    let read_write = || {
        let info = std::fs::read_to_string("/proc/self/fdinfo/1").unwrap_or_default();
        info.lines()
            .find_map(|l| l.strip_prefix("flags:"))
            .and_then(|flags| u32::from_str_radix(flags.trim(), 8).ok())
            .is_some_and(|flags| flags & 0o3 == 0o2)
    };
    null && read_write()
}

#[cfg(not(target_os = "linux"))]
fn standard_output_was_closed() -> bool {
    false
}

#[cfg(unix)]
fn standard_output_file() -> std::io::Result<File> {
    use std::os::fd::AsFd;
    // Duplicating fails with EBADF when descriptor 1 is closed.
    let fd = std::io::stdout().as_fd().try_clone_to_owned()?;
    Ok(File::from(fd))
}

#[cfg(not(unix))]
fn standard_output_file() -> std::io::Result<Box<dyn Write>> {
    Ok(Box::new(std::io::stdout()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file in a folder of the test's own (tests run at once, and one lists its folder).
    fn scratch(test: &str, name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("cutroute-output-{}-{test}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    #[test]
    fn a_failed_write_keeps_the_old_file_and_leaves_no_part() {
        let file = scratch("failed", "kept.json");
        write_output(&file, b"first").unwrap();
        write_output(&file, b"second").unwrap();
        assert_eq!(std::fs::read(&file).unwrap(), b"second");
        // A destination that cannot be replaced (a directory): an error, and no part file left.
        let blocked = scratch("failed", "blocked");
        std::fs::create_dir_all(blocked.join("inside")).unwrap();
        assert!(write_output(&blocked, b"x").is_err());
        assert!(blocked.join("inside").is_dir());
        // A folder that does not exist: an error naming the file.
        let nowhere = scratch("failed", "missing-folder").join("out.json");
        let error = write_output(&nowhere, b"x").unwrap_err();
        assert!(error.contains("out.json"), "{error}");
        let leftovers: Vec<_> = std::fs::read_dir(file.parent().unwrap())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".part"))
            .collect();
        assert!(leftovers.is_empty(), "{leftovers:?}");
    }

    #[test]
    fn the_same_file_under_another_name_is_refused() {
        let file = scratch("same", "same.json");
        std::fs::write(&file, b"{}").unwrap();
        let dotted = file.parent().unwrap().join(".").join("same.json");
        assert!(refuse_overwriting_inputs(&dotted, [file.as_path()]).is_err());
        let other = scratch("same", "other.json");
        assert!(refuse_overwriting_inputs(&other, [file.as_path()]).is_ok());
        assert!(refuse_overwriting_inputs(Path::new("-"), [Path::new("-")]).is_ok());
    }

    #[cfg(unix)]
    #[test]
    fn permissions_and_links_are_kept() {
        use std::os::unix::fs::PermissionsExt;
        let file = scratch("modes", "mode.nc");
        std::fs::write(&file, b"old").unwrap();
        std::fs::set_permissions(&file, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_output(&file, b"new").unwrap();
        let mode = std::fs::metadata(&file).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o640);
        let link = scratch("modes", "link.nc");
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink(&file, &link).unwrap();
        write_output(&link, b"through the link").unwrap();
        assert!(std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink());
        assert_eq!(std::fs::read(&file).unwrap(), b"through the link");
    }
}
