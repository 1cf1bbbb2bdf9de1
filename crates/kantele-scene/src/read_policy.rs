//! Confined reads: which files a scene may read.
//!
//! By default a scene reads only regular files inside its own folder (after resolving `..` and
//! symbolic links); [`LoadOptions::allow_read`](crate::LoadOptions::allow_read) adds folders.
//! Devices, FIFOs, sockets and folders are never read, and a file larger than the memory budget
//! allows is refused before it is read.
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
        let real = std::fs::canonicalize(file).map_err(|e| format!("cannot read {shown}: {e}"))?;
        if !self.roots.iter().any(|root| real.starts_with(root)) {
            return Err(format!(
                "{shown} lies outside the scene's folder; allow it with --allow-read DIR"
            ));
        }
        read_regular_file(&real, budget).map_err(|e| format!("cannot read {shown}: {e}"))
    }
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
    let meta = std::fs::metadata(file).map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err("not a regular file".to_string());
    }
    budget.charge(meta.len(), 1, "reading the file")?;
    let f = std::fs::File::open(file).map_err(|e| e.to_string())?;
    // Re-check on the opened handle: the path may have been swapped since `metadata`.
    let meta = f.metadata().map_err(|e| e.to_string())?;
    if !meta.is_file() {
        return Err("not a regular file".to_string());
    }
    let len = usize::try_from(meta.len()).map_err(|_| "too large".to_string())?;
    let mut bytes = crate::budget::vec_with_capacity(len, "reading the file")?;
    // Never read past the size that was charged, even if the file grows meanwhile.
    f.take(meta.len())
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
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
}
