//! The material libraries an OBJ file names, on one `mtllib` line or several
//! (`mtllib a.mtl b.mtl`): found relative to the OBJ file's folder, read under the read policy
//! and the budget, each once, and handed to `tobj` by name (it only resolves `usemtl`); the
//! loader keeps what they say ([`MtlLibraries::materials`]).
//!
//! A `mtllib` value that names an existing file as a whole is one name (names may hold
//! spaces); otherwise each word is a name. At most [`MAX_LIBRARIES`] libraries are read.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use crate::budget::Budget;
use crate::mtl::{parse_mtl, MtlMaterial};
use crate::obj_text::{text, UNNAMED_MATERIAL};
use crate::read_policy::ReadPolicy;

/// The most material libraries one OBJ file may have read; the names after that are skipped
/// with a warning.
pub(crate) const MAX_LIBRARIES: usize = 64;

/// Lines of one library that get a warning of their own; the others are counted in one line.
pub(crate) const MAX_LINE_WARNINGS: usize = 16;

/// Bytes charged per byte of MTL text, for its decoded copy and what is parsed from it.
const MTL_BYTES_PER_TEXT_BYTE: u64 = 4;

/// The material libraries read so far, and what went wrong.
#[derive(Debug)]
pub(crate) struct MtlLibraries<'a> {
    /// The OBJ file's folder.
    directory: &'a Path,
    /// Where reads may go.
    policy: &'a ReadPolicy,
    /// Every material read, in `tobj`'s order, with the folder of its library (texture names
    /// are relative to it).
    pub materials: Vec<(MtlMaterial, PathBuf)>,
    /// The libraries read or tried.
    tried: HashSet<PathBuf>,
    /// Whether more than [`MAX_LIBRARIES`] were named (warned once).
    limit_reached: bool,
    /// Problems that did not stop loading.
    pub warnings: Vec<String>,
    /// Statements of the libraries that are not drawn, once each.
    pub ignored: Vec<String>,
    /// The first library that could not be read (an error under `strict`).
    pub first_missing: Option<String>,
    /// What stops the load (the budget ran out); nothing more is read after it.
    pub fatal: Option<String>,
}

impl<'a> MtlLibraries<'a> {
    /// No libraries yet, for an OBJ file in `directory`.
    pub(crate) fn new(directory: &'a Path, policy: &'a ReadPolicy) -> Self {
        Self {
            directory,
            policy,
            materials: Vec::new(),
            tried: HashSet::new(),
            limit_reached: false,
            warnings: Vec::new(),
            ignored: Vec::new(),
            first_missing: None,
            fatal: None,
        }
    }

    /// The file a library name stands for.
    fn file(&self, name: &str) -> PathBuf {
        self.directory.join(name.replace('\\', "/"))
    }

    /// The names in a `mtllib` value.
    fn names<'v>(&self, value: &'v str) -> Vec<&'v str> {
        let value = value.trim();
        let unquoted = value
            .strip_prefix('"')
            .and_then(|v| v.strip_suffix('"'))
            .unwrap_or(value);
        if unquoted.is_empty() {
            Vec::new()
        } else if self.file(unquoted).is_file() {
            vec![unquoted]
        } else {
            value.split_whitespace().collect()
        }
    }

    /// Reads the libraries of one `mtllib` value; returns their materials as `tobj` wants
    /// them (names only, empty names replaced by [`UNNAMED_MATERIAL`]).
    pub(crate) fn load(&mut self, value: &str, budget: &mut Budget) -> tobj::MTLLoadResult {
        let first = self.materials.len();
        for name in self.names(value) {
            if self.fatal.is_some() {
                break;
            }
            let file = self.file(name);
            if self.tried.contains(&file) {
                continue;
            }
            if self.tried.len() >= MAX_LIBRARIES {
                if !self.limit_reached {
                    self.limit_reached = true;
                    self.warnings.push(format!(
                        "the file names more than {MAX_LIBRARIES} material libraries; the others are not read"
                    ));
                }
                break;
            }
            self.tried.insert(file.clone());
            if let Err(e) = self.read(name, &file, budget) {
                let message = format!("material library {name}: {e}");
                if e.contains("memory budget") {
                    self.fatal = Some(message);
                } else {
                    self.first_missing.get_or_insert_with(|| message.clone());
                    self.warnings.push(message);
                }
            }
        }
        // `tobj`'s own map type (whichever hasher its features choose).
        let mut result: tobj::MTLLoadResult = Ok(Default::default());
        if let Ok((materials, names)) = &mut result {
            for (index, (m, _)) in self.materials[first..].iter().enumerate() {
                let name = if m.name.is_empty() {
                    UNNAMED_MATERIAL.to_string()
                } else {
                    m.name.clone()
                };
                // A later material of the same name wins, as in `tobj`.
                names.insert(name.clone(), index);
                materials.push(tobj::Material {
                    name,
                    ..tobj::Material::default()
                });
            }
        }
        result
    }

    /// Reads and parses one library.
    fn read(&mut self, name: &str, file: &Path, budget: &mut Budget) -> Result<(), String> {
        let bytes = self.policy.read(file, budget)?;
        budget.charge(
            bytes.len() as u64,
            MTL_BYTES_PER_TEXT_BYTE,
            "reading the MTL text",
        )?;
        let library = parse_mtl(&text(&bytes), budget)?;
        let unread = library.warnings.len();
        for w in library.warnings.into_iter().take(MAX_LINE_WARNINGS) {
            self.warnings.push(format!("material library {name}: {w}"));
        }
        if unread > MAX_LINE_WARNINGS {
            self.warnings.push(format!(
                "material library {name}: {} more lines could not be read",
                unread - MAX_LINE_WARNINGS
            ));
        }
        for i in library.ignored {
            if !self.ignored.contains(&i) {
                self.ignored.push(i);
            }
        }
        let folder = file.parent().unwrap_or(Path::new("")).to_path_buf();
        self.materials
            .extend(library.materials.into_iter().map(|m| (m, folder.clone())));
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_read_once_missing_ones_and_the_limit() {
        let dir = std::env::temp_dir().join(format!("kantele-mtllib-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("a.mtl"), "newmtl red\nKd 1 0 0\nnewmtl\n").unwrap();
        std::fs::write(dir.join("with space.mtl"), "newmtl blue\n").unwrap();
        std::fs::write(dir.join("bad.mtl"), "newmtl bad\nKd x\n".repeat(1000)).unwrap();
        let scene = dir.join("s.obj");
        let policy = ReadPolicy::new(&scene, &[]);
        let mut budget = Budget::new(1 << 30);
        let mut libraries = MtlLibraries::new(&dir, &policy);
        let (materials, names) = libraries.load("gone.mtl a.mtl a.mtl", &mut budget).unwrap();
        assert_eq!(materials.len(), 2);
        assert_eq!(names[UNNAMED_MATERIAL], 1);
        assert_eq!(libraries.warnings.len(), 1, "{:?}", libraries.warnings);
        assert!(libraries
            .first_missing
            .as_deref()
            .unwrap()
            .contains("gone.mtl"));
        // Read once: naming it again adds nothing.
        let (materials, _) = libraries.load("a.mtl", &mut budget).unwrap();
        assert!(materials.is_empty());
        let (materials, _) = libraries.load(" with space.mtl ", &mut budget).unwrap();
        assert_eq!(materials[0].name, "blue");
        assert_eq!(libraries.materials.len(), 3);
        // A library of bad lines: MAX_LINE_WARNINGS of them, and a count.
        let before = libraries.warnings.len();
        libraries.load("bad.mtl", &mut budget).unwrap();
        assert_eq!(libraries.warnings.len(), before + MAX_LINE_WARNINGS + 1);
        assert!(libraries
            .warnings
            .last()
            .unwrap()
            .contains("984 more lines"));
        libraries.warnings.truncate(before);
        // Many names: at most MAX_LIBRARIES are tried, with one warning.
        let many: Vec<String> = (0..1000).map(|i| format!("m{i}.mtl")).collect();
        libraries.load(&many.join(" "), &mut budget).unwrap();
        libraries.load("more.mtl", &mut budget).unwrap();
        let limit = libraries
            .warnings
            .iter()
            .filter(|w| w.contains("more than"))
            .count();
        assert_eq!(limit, 1);
        assert_eq!(libraries.warnings.len(), MAX_LIBRARIES - 4 + 1 + 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
