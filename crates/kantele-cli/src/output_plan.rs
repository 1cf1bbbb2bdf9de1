//! Checks on output files made before anything is rendered: no two outputs the same file, no
//! output overwriting an input (a scene file or a file it references), every output folder
//! created and writable.
//!
//! The inputs are known twice: before any scene is loaded, from the files a `.gltf` or `.obj`
//! names ([`input_files`], read only if they are small regular files), and after each load,
//! exactly, from the files the loader read ([`OutputGuard::check_reads`]), which catches every
//! form of reference (a `.glb`'s image URIs, `file://` URIs, MTL maps with options).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Result};

use crate::scenes::Input;

/// The identity of a path for comparisons: absolute, `.`/`..` resolved, symbolic links of the
/// existing part followed ([`kantele_scene::resolved_path`]).
pub fn identity(path: &Path) -> PathBuf {
    kantele_scene::resolved_path(path)
}

/// The most bytes of a `.gltf`, `.obj` or `.mtl` text [`input_files`] reads to find the files
/// it names; a larger text is protected itself, and its references after loading.
const LISTING_LIMIT: u64 = 64 << 20;

/// The bytes of `path` if it is a regular file of at most [`LISTING_LIMIT`] bytes: never a
/// device, FIFO or socket (opening a FIFO would wait for a writer), never more than the limit.
fn read_listing(path: &Path) -> Option<Vec<u8>> {
    use std::io::Read;
    let meta = std::fs::metadata(path).ok()?;
    if !meta.is_file() || meta.len() > LISTING_LIMIT {
        return None;
    }
    let file = std::fs::File::open(path).ok()?;
    // The path may have been swapped since: check what was opened.
    if !file.metadata().ok()?.is_file() {
        return None;
    }
    let mut bytes = Vec::new();
    file.take(LISTING_LIMIT).read_to_end(&mut bytes).ok()?;
    Some(bytes)
}

/// Files an input reads, as far as can be told before loading it: the scene file and, for
/// `.gltf` and `.obj`, the files it names (buffers, images, MTL libraries and their texture
/// maps) next to it.
pub fn input_files(input: &Input) -> Vec<PathBuf> {
    let Input::File(path, _) = input else {
        return Vec::new();
    };
    let mut files = vec![path.clone()];
    let dir = path.parent().unwrap_or(Path::new(""));
    match crate::output::extension(path).as_str() {
        "gltf" => {
            let Some(text) = read_listing(path).and_then(|b| String::from_utf8(b).ok()) else {
                return files;
            };
            let Ok(json) = serde_json::from_str::<serde_json::Value>(&text) else {
                return files;
            };
            for list in ["buffers", "images"] {
                for item in json[list].as_array().into_iter().flatten() {
                    if let Some(uri) = item["uri"].as_str() {
                        if !uri.starts_with("data:") {
                            files.push(dir.join(percent_decode(uri)));
                        }
                    }
                }
            }
        }
        "obj" => {
            let Some(bytes) = read_listing(path) else {
                return files;
            };
            let text = kantele_scene::obj_text(&bytes);
            for lib in names_after(&text, |k| k == "mtllib") {
                let mtl = dir.join(&lib);
                if let Some(mtl_bytes) = read_listing(&mtl) {
                    let mtl_text = kantele_scene::obj_text(&mtl_bytes);
                    let mtl_dir = mtl.parent().unwrap_or(Path::new("")).to_path_buf();
                    for map in names_after(&mtl_text, is_texture_statement) {
                        files.push(mtl_dir.join(map));
                    }
                }
                files.push(mtl);
            }
        }
        _ => {}
    }
    files
}

/// MTL statements that name a texture file (`map_Kd`, `map_Ke`, `map_Pr`, `bump`, `norm`, …).
fn is_texture_statement(keyword: &str) -> bool {
    keyword.starts_with("map_") || ["bump", "norm", "disp", "decal", "refl"].contains(&keyword)
}

/// Every name the value of a statement whose keyword (lowercased) `keyword` accepts may stand
/// for: each run of consecutive words of the value (each run for values of at most 16 words,
/// else each word and each run of last words). A list of names (`mtllib a.mtl b.mtl`), a name
/// with spaces and a name after options (`map_Kd -s 1 1 1 wood.png`) are all among them;
/// guarding more names than the loader reads is harmless.
fn names_after(text: &str, keyword: impl Fn(&str) -> bool) -> Vec<String> {
    let mut names = Vec::new();
    for line in text.lines() {
        let mut words = line.split_whitespace();
        let Some(first) = words.next() else {
            continue;
        };
        if !keyword(&first.to_ascii_lowercase()) {
            continue;
        }
        let words: Vec<&str> = words.collect();
        let n = words.len();
        for start in 0..n {
            for end in start + 1..=n {
                if n <= 16 || end == start + 1 || end == n {
                    names.push(words[start..end].join(" "));
                }
            }
        }
    }
    names
}

fn percent_decode(uri: &str) -> String {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            // Two hex digits as bytes: a multi-byte character after '%' is no escape (and
            // slicing the text there would cut the character).
            let hex = std::str::from_utf8(&bytes[i + 1..i + 3]).ok();
            if let Some(b) = hex.and_then(|h| u8::from_str_radix(h, 16).ok()) {
                out.push(b);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Collects outputs and refuses duplicates and inputs.
#[derive(Default)]
pub struct OutputGuard {
    inputs: HashMap<PathBuf, PathBuf>,
    outputs: HashMap<PathBuf, PathBuf>,
}

impl OutputGuard {
    /// A guard protecting the files of `inputs`.
    pub fn new(inputs: &[Input]) -> Self {
        let mut guard = Self::default();
        for input in inputs {
            for f in input_files(input) {
                guard.inputs.insert(identity(&f), f);
            }
        }
        guard
    }

    /// Protects one more file (e.g. a `--views` file).
    pub fn protect(&mut self, path: &Path) {
        self.inputs.insert(identity(path), path.to_path_buf());
    }

    /// Records an output; an input or an earlier output at the same place is an error.
    pub fn add(&mut self, path: &Path) -> Result<()> {
        let id = identity(path);
        if let Some(input) = self.inputs.get(&id) {
            bail!(
                "{}: would overwrite the input {}; choose another output name",
                path.display(),
                input.display()
            );
        }
        if let Some(earlier) = self.outputs.insert(id, path.to_path_buf()) {
            bail!(
                "{}: would be written more than once (also as {}); make the output names unique with {{stem}}, {{index}} or {{frame}}",
                path.display(),
                earlier.display()
            );
        }
        Ok(())
    }

    /// Refuses outputs that would overwrite a file a loaded scene read (`files`: the loader's
    /// [`files_read`](kantele_scene::SceneInfo::files_read)); `label` names the scene.
    pub fn check_reads(&self, label: &str, files: &[PathBuf]) -> Result<()> {
        for file in files {
            if let Some(output) = self.outputs.get(&identity(file)) {
                bail!(
                    "{}: would overwrite {}, which {label} reads; choose another output name",
                    output.display(),
                    file.display()
                );
            }
        }
        Ok(())
    }

    /// Creates every output folder and checks it is a writable folder.
    pub fn create_folders(&self) -> Result<()> {
        let mut done = std::collections::HashSet::new();
        for path in self.outputs.values() {
            let dir = match path.parent() {
                Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
                _ => PathBuf::from("."),
            };
            if !done.insert(dir.clone()) {
                continue;
            }
            create_folder(&dir)?;
        }
        Ok(())
    }
}

/// Creates `dir` (and its parents) and checks that a file can be made in it.
pub fn create_folder(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir)
        .map_err(|e| anyhow!("{}: cannot create the folder: {e}", dir.display()))?;
    let probe = dir.join(format!(".kantele-probe-{}", std::process::id()));
    std::fs::File::create(&probe)
        .map_err(|e| anyhow!("{}: cannot write in this folder: {e}", dir.display()))?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tmp(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("kantele-plan-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn refuses_inputs_and_duplicates() {
        let d = tmp("guard");
        std::fs::write(
            d.join("s.gltf"),
            r#"{"asset":{"version":"2.0"},"buffers":[{"uri":"b%20in.bin"}],"images":[{"uri":"tex/a.png"},{"uri":"data:x"}]}"#,
        )
        .unwrap();
        let input = Input::File(d.join("s.gltf"), Default::default());
        let files = input_files(&input);
        assert!(files.contains(&d.join("b in.bin")));
        assert!(files.contains(&d.join("tex/a.png")));
        assert_eq!(files.len(), 3);
        let mut g = OutputGuard::new(&[input]);
        assert!(g.add(&d.join("s.gltf")).is_err());
        assert!(g.add(&d.join("sub/../tex/a.png")).is_err());
        assert!(g.add(&d.join("out.png")).is_ok());
        assert!(g.add(&d.join("./out.png")).is_err());
        g.add(&d.join("new/deeper/x.png")).unwrap();
        g.create_folders().unwrap();
        assert!(d.join("new/deeper").is_dir());
        std::fs::write(d.join("afile"), b"x").unwrap();
        let mut g2 = OutputGuard::default();
        g2.add(&d.join("afile/x.png")).unwrap();
        assert!(g2.create_folders().is_err());
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// Several libraries after one `mtllib`, names with spaces, UTF-16 text and every texture
    /// statement the loader reads are guarded.
    #[test]
    fn obj_inputs_include_every_library_and_map_the_loader_reads() {
        let d = tmp("obj-exported");
        let obj = "mtllib a.mtl other.mtl\nmtllib b c.mtl\nv 0 0 0\n";
        let mut utf16 = vec![0xff, 0xfe];
        utf16.extend(obj.encode_utf16().flat_map(u16::to_le_bytes));
        std::fs::write(d.join("m.obj"), utf16).unwrap();
        std::fs::write(
            d.join("a.mtl"),
            "newmtl a\nmap_Ke glow.png\nnorm -bm 0.5 n.png\n",
        )
        .unwrap();
        std::fs::write(
            d.join("b c.mtl"),
            "newmtl b\nmap_Pr rough map.png\nmap_Pm -imfchan b m.png\n",
        )
        .unwrap();
        let files = input_files(&Input::File(d.join("m.obj"), Default::default()));
        for name in [
            "a.mtl",
            "b c.mtl",
            "glow.png",
            "n.png",
            "rough map.png",
            "m.png",
        ] {
            assert!(
                files.contains(&d.join(name)),
                "{name} is not guarded: {files:?}"
            );
        }
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn obj_inputs_include_mtl_and_maps() {
        let d = tmp("obj");
        std::fs::write(d.join("m.obj"), "mtllib m.mtl\nv 0 0 0\n").unwrap();
        std::fs::write(d.join("m.mtl"), "newmtl a\nmap_Kd -s 1 1 1 wood.png\n").unwrap();
        let files = input_files(&Input::File(d.join("m.obj"), Default::default()));
        assert!(files.contains(&d.join("m.mtl")));
        assert!(files.contains(&d.join("wood.png")));
        std::fs::remove_dir_all(&d).unwrap();
    }

    /// Percent escapes decode to bytes; a '%' before non-hex or non-ASCII text stays as it is,
    /// whatever characters follow (no panic on a character cut in the middle).
    #[test]
    fn percent_decoding_survives_any_text() {
        assert_eq!(percent_decode("a%20b.png"), "a b.png");
        assert_eq!(percent_decode("%C3%A9.png"), "é.png");
        for uri in [
            "%1é.png", "%é", "%", "%%", "%2", "é%", "%zz", "%%41", "ü%e9x",
        ] {
            let _ = percent_decode(uri);
        }
        assert_eq!(percent_decode("%1é.png"), "%1é.png");
        assert_eq!(percent_decode("%%41"), "%A");
    }
}
