//! Confined reads: which files a scene may read.
//!
//! By default a scene reads only regular files inside its own folder (after resolving `..` and
//! symbolic links); [`LoadOptions::allow_read`](crate::LoadOptions::allow_read) adds folders.
//! Devices, FIFOs, sockets and folders are never read, and a file larger than the memory budget
//! allows is refused before it is read.
//!
//! The check holds for the file actually opened: after opening, the open file's own path (on
//! Linux, as the kernel gives it; elsewhere, the path resolved again, which must name the very
//! file opened) must still lie inside, so a folder swapped for a symbolic link between the
//! check and the open is refused. A path outside the allowed
//! folders gets the same error whether or not a file is there (no existence oracle).
//!
//! Every file a load reads is recorded ([`record_reads`]): the command compares its outputs with
//! them, so no output overwrites a file the scene was made from, whatever form its reference
//! took (a relative URI, `file://`, an MTL map).

use std::cell::RefCell;
use std::io::Read;
use std::path::{Path, PathBuf};

use crate::budget::Budget;
use crate::LoadError;

/// The folders a load may read from (canonical paths).
#[derive(Debug)]
pub(crate) struct ReadPolicy {
    roots: Vec<PathBuf>,
}

impl ReadPolicy {
    /// The policy for the scene at `scene`: its own folder plus `allow_read`. Folders that do
    /// not exist are left out.
    pub(crate) fn new(scene: &Path, allow_read: &[PathBuf]) -> Self {
        let own = scene
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let roots = std::iter::once(own)
            .chain(allow_read.iter().map(PathBuf::as_path))
            .filter_map(|p| std::fs::canonicalize(p).ok())
            .collect();
        Self { roots }
    }

    /// Reads `file` (a file the scene refers to) if the policy allows it; the error says why
    /// not.
    pub(crate) fn read(&self, file: &Path, budget: &mut Budget) -> Result<Vec<u8>, String> {
        let shown = file.display();
        let outside =
            || format!("{shown} lies outside the scene's folder; allow it with --allow-read DIR");
        // Where the path leads, whether or not a file is there: outside is outside either way.
        let place = resolved(file);
        if !self.inside(&place) {
            return Err(outside());
        }
        let real = std::fs::canonicalize(file).map_err(|e| format!("cannot read {shown}: {e}"))?;
        if !self.inside(&real) {
            return Err(outside());
        }
        read_opened(&real, budget, |opened| {
            self.still_inside(file, opened)
                .then_some(())
                .ok_or_else(outside)
        })
        .map_err(|e| match e {
            OpenedRead::Refused(e) => e,
            OpenedRead::Failed(e) => format!("cannot read {shown}: {e}"),
        })
    }

    fn inside(&self, path: &Path) -> bool {
        self.roots.iter().any(|root| path.starts_with(root))
    }

    /// Whether the file `opened` lies inside: on Linux, the path the kernel gives for the open
    /// file (`/proc/self/fd/N`, which no later swap can change); elsewhere, `file` resolved
    /// again must lie inside and be that very file (same device and inode): not a path whose
    /// folders were swapped in between.
    fn still_inside(&self, file: &Path, opened: &std::fs::File) -> bool {
        #[cfg(target_os = "linux")]
        {
            use std::os::fd::AsRawFd;
            let link = format!("/proc/self/fd/{}", opened.as_raw_fd());
            if let Ok(actual) = std::fs::read_link(link) {
                return self.inside(&actual);
            }
        }
        let Ok(now) = std::fs::canonicalize(file) else {
            return false;
        };
        if !self.inside(&now) {
            return false;
        }
        same_file(opened, &now)
    }
}

/// Whether `opened` is the file at `path` (device and inode; on systems without them, yes).
fn same_file(opened: &std::fs::File, path: &Path) -> bool {
    #[cfg(unix)]
    {
        use std::os::unix::fs::MetadataExt;
        match (opened.metadata(), std::fs::metadata(path)) {
            (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
            _ => false,
        }
    }
    #[cfg(not(unix))]
    {
        let _ = (opened, path);
        true
    }
}

/// Where `path` leads: its canonical form when it exists, else its longest existing ancestor's
/// canonical form with the rest appended (`.` and `..` resolved by name).
pub(crate) fn resolved(path: &Path) -> PathBuf {
    if let Ok(real) = std::fs::canonicalize(path) {
        return real;
    }
    let absolute = std::env::current_dir()
        .map(|d| d.join(path))
        .unwrap_or_else(|_| path.to_path_buf());
    // The longest existing ancestor, resolved; the rest appended, then `.` and `..` resolved
    // by name over the whole path.
    let mut existing = absolute.clone();
    let mut rest = Vec::new();
    while !existing.exists() {
        match (existing.file_name(), existing.parent()) {
            (Some(name), Some(parent)) => {
                rest.push(name.to_os_string());
                existing = parent.to_path_buf();
            }
            _ => break,
        }
    }
    let mut out = std::fs::canonicalize(&existing).unwrap_or(existing);
    for part in rest.iter().rev() {
        out.push(part);
    }
    let mut clean = PathBuf::new();
    for c in out.components() {
        match c {
            std::path::Component::ParentDir => {
                clean.pop();
            }
            std::path::Component::CurDir => {}
            other => clean.push(other),
        }
    }
    clean
}

/// Why [`read_opened`] read nothing.
enum OpenedRead {
    /// The opened file failed the caller's check.
    Refused(String),
    /// The file could not be opened or read, or is not a regular file.
    Failed(String),
}

thread_local! {
    /// The files read on this thread inside [`record_reads`], canonical; `None` outside it.
    static READ_LOG: RefCell<Option<Vec<PathBuf>>> = const { RefCell::new(None) };
}

/// Runs `load` and returns, with its result, the canonical paths of every file it read through
/// [`read_regular_file`] on this thread, in reading order, once each.
pub(crate) fn record_reads<T>(load: impl FnOnce() -> T) -> (T, Vec<PathBuf>) {
    let outer = READ_LOG.with(|log| log.borrow_mut().replace(Vec::new()));
    let result = load();
    let files = READ_LOG.with(|log| std::mem::replace(&mut *log.borrow_mut(), outer));
    (result, files.unwrap_or_default())
}

/// Notes that `file` was read, when inside [`record_reads`].
fn log_read(file: &Path) {
    READ_LOG.with(|log| {
        if let Some(files) = log.borrow_mut().as_mut() {
            let real = std::fs::canonicalize(file).unwrap_or_else(|_| file.to_path_buf());
            if !files.contains(&real) {
                files.push(real);
            }
        }
    });
}

/// Reads a regular file (never a device, FIFO or folder), charging its size to the budget
/// before reading; the read is recorded ([`record_reads`]).
pub(crate) fn read_regular_file(file: &Path, budget: &mut Budget) -> Result<Vec<u8>, String> {
    read_opened(file, budget, |_| Ok(())).map_err(|e| match e {
        OpenedRead::Refused(e) | OpenedRead::Failed(e) => e,
    })
}

/// [`read_regular_file`], with `check` run on the opened file before anything is read from it.
fn read_opened(
    file: &Path,
    budget: &mut Budget,
    check: impl FnOnce(&std::fs::File) -> Result<(), String>,
) -> Result<Vec<u8>, OpenedRead> {
    let failed = |e: String| OpenedRead::Failed(e);
    let meta = std::fs::metadata(file).map_err(|e| failed(e.to_string()))?;
    if !meta.is_file() {
        return Err(failed("not a regular file".to_string()));
    }
    budget
        .charge(meta.len(), 1, "reading the file")
        .map_err(failed)?;
    let f = std::fs::File::open(file).map_err(|e| failed(e.to_string()))?;
    // Re-check on the opened handle: the path may have been swapped since `metadata`.
    let meta = f.metadata().map_err(|e| failed(e.to_string()))?;
    if !meta.is_file() {
        return Err(failed("not a regular file".to_string()));
    }
    check(&f).map_err(OpenedRead::Refused)?;
    let read = || -> Result<Vec<u8>, String> {
        let len = usize::try_from(meta.len()).map_err(|_| "too large".to_string())?;
        let mut bytes = crate::budget::vec_with_capacity(len, "reading the file")?;
        // Never read past the size that was charged, even if the file grows meanwhile.
        f.take(meta.len())
            .read_to_end(&mut bytes)
            .map_err(|e| e.to_string())?;
        Ok(bytes)
    };
    let bytes = read().map_err(failed)?;
    log_read(file);
    Ok(bytes)
}

/// The bytes of the scene file a load starts from, with the load's budget (`max_memory`) already
/// charged for them: a missing file is [`LoadError::Io`], anything else that stops the read a
/// one-line error naming the file.
pub(crate) fn read_scene_file(
    path: &Path,
    max_memory: u64,
) -> Result<(Vec<u8>, Budget), LoadError> {
    std::fs::metadata(path).map_err(|source| LoadError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    let mut budget = Budget::new(max_memory);
    let bytes = read_regular_file(path, &mut budget).map_err(|e| LoadError::invalid(path, e))?;
    Ok((bytes, budget))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_inside_and_refuses_outside_and_special_files() {
        let dir = std::env::temp_dir().join(format!("kantele-policy-{}", std::process::id()));
        let inner = dir.join("scene");
        std::fs::create_dir_all(&inner).unwrap();
        std::fs::write(inner.join("a.bin"), b"abc").unwrap();
        std::fs::write(dir.join("secret.bin"), b"secret").unwrap();
        let mut budget = Budget::new(1 << 20);
        let policy = ReadPolicy::new(&inner.join("s.gltf"), &[]);
        assert_eq!(
            policy.read(&inner.join("a.bin"), &mut budget).unwrap(),
            b"abc"
        );
        let e = policy
            .read(&inner.join("../secret.bin"), &mut budget)
            .unwrap_err();
        assert!(e.contains("outside the scene's folder"), "{e}");
        let e = policy
            .read(Path::new("/dev/zero"), &mut budget)
            .unwrap_err();
        assert!(e.contains("outside"), "{e}");
        let e = policy.read(&inner, &mut budget).unwrap_err();
        assert!(e.contains("not a regular file"), "{e}");
        let widened = ReadPolicy::new(&inner.join("s.gltf"), std::slice::from_ref(&dir));
        assert_eq!(
            widened
                .read(&inner.join("../secret.bin"), &mut budget)
                .unwrap(),
            b"secret"
        );
        let e = ReadPolicy::new(&inner.join("s.gltf"), &[PathBuf::from("/dev")])
            .read(Path::new("/dev/zero"), &mut budget)
            .unwrap_err();
        assert!(e.contains("not a regular file"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A path outside the allowed folders gets the same error whether or not a file is there.
    #[test]
    fn outside_is_outside_whether_or_not_the_file_exists() {
        let dir = std::env::temp_dir().join(format!("kantele-oracle-{}", std::process::id()));
        let inner = dir.join("scene");
        std::fs::create_dir_all(&inner).unwrap();
        std::fs::write(dir.join("exists.bin"), b"x").unwrap();
        let mut budget = Budget::new(1 << 20);
        let policy = ReadPolicy::new(&inner.join("s.gltf"), &[]);
        let mut error = |name: &str| {
            let e = policy
                .read(&inner.join(format!("../{name}")), &mut budget)
                .unwrap_err();
            e.replace(name, "NAME")
        };
        assert_eq!(error("exists.bin"), error("missing.bin"));
        assert!(error("missing.bin").contains("outside the scene's folder"));
        assert!(error("no/such/folder.bin").contains("outside the scene's folder"));
        // Inside, a missing file says so.
        let e = policy
            .read(&inner.join("missing.bin"), &mut budget)
            .unwrap_err();
        assert!(e.contains("cannot read"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A folder inside the scene's folder swapped, again and again, for a symbolic link to a
    /// folder outside (between the check and the open): no read ever returns the outside file,
    /// because the check holds for the file opened, not for the path checked.
    #[cfg(unix)]
    #[test]
    fn a_folder_swapped_for_a_link_never_leaks() {
        use std::sync::atomic::{AtomicBool, Ordering};
        let dir = std::env::temp_dir().join(format!("kantele-swap-{}", std::process::id()));
        let inner = dir.join("scene");
        let real = inner.join("real");
        let parked = inner.join("parked");
        let outside = dir.join("outside");
        std::fs::create_dir_all(&real).unwrap();
        std::fs::create_dir_all(&outside).unwrap();
        std::fs::write(real.join("a.bin"), b"inside").unwrap();
        std::fs::write(outside.join("a.bin"), b"secret").unwrap();
        let stop = AtomicBool::new(false);
        let policy = ReadPolicy::new(&inner.join("s.gltf"), &[]);
        let (mut inside_reads, mut refused, mut leaked) = (0, 0, 0);
        std::thread::scope(|scope| {
            scope.spawn(|| {
                while !stop.load(Ordering::Relaxed) {
                    // `real` becomes a link to the outside folder, then the folder again.
                    let _ = std::fs::rename(&real, &parked);
                    let _ = std::os::unix::fs::symlink(&outside, &real);
                    let _ = std::fs::remove_file(&real);
                    let _ = std::fs::rename(&parked, &real);
                }
            });
            for _ in 0..3000 {
                let mut budget = Budget::new(1 << 20);
                match policy.read(&real.join("a.bin"), &mut budget) {
                    Ok(bytes) if bytes == b"inside" => inside_reads += 1,
                    Ok(_) => leaked += 1,
                    Err(_) => refused += 1,
                }
            }
            stop.store(true, Ordering::Relaxed);
        });
        assert_eq!(leaked, 0, "reads outside the scene's folder");
        assert_eq!(inside_reads + refused, 3000);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
