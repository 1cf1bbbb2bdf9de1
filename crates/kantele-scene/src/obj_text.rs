//! OBJ and MTL text made safe for `tobj`, which panics or fails on some valid or harmless
//! input: bytes that are not UTF-8 are read as Latin-1, one-value colour lines (`Kd 0.8`) are
//! widened, malformed colour lines are dropped with a warning, empty material names get a
//! name, and `l` / `p` lines (lines and points) are taken out instead of being read as faces
//! (`obj_wide` reads them).

/// The name given to materials declared with an empty `newmtl` (and used by an empty
/// `usemtl`); reported as an empty name.
pub(crate) const UNNAMED_MATERIAL: &str = "kantele-unnamed-material";

/// Text from bytes: UTF-8 when valid, otherwise Latin-1 (every byte one character).
pub(crate) fn text(bytes: &[u8]) -> String {
    match std::str::from_utf8(bytes) {
        Ok(s) => s.to_string(),
        Err(_) => bytes.iter().map(|&b| b as char).collect(),
    }
}

/// What patching an OBJ file found.
#[derive(Debug, Default, PartialEq)]
pub(crate) struct ObjPatch {
    /// The patched text.
    pub text: String,
    /// Number of `l` (polyline) statements taken out.
    pub lines: usize,
    /// Number of `p` (point) statements taken out.
    pub points: usize,
}

/// Patches OBJ text for `tobj`.
pub(crate) fn patch_obj(source: &str) -> ObjPatch {
    let mut out = ObjPatch {
        text: String::with_capacity(source.len()),
        ..ObjPatch::default()
    };
    for line in source.lines() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("l") => out.lines += 1,
            Some("p") => out.points += 1,
            Some("usemtl") if words.next().is_none() => {
                out.text.push_str("usemtl ");
                out.text.push_str(UNNAMED_MATERIAL);
                out.text.push('\n');
            }
            _ => {
                out.text.push_str(line);
                out.text.push('\n');
            }
        }
    }
    out
}

/// Patches MTL text for `tobj`; returns the text and one warning per line it had to drop.
pub(crate) fn patch_mtl(source: &str) -> (String, Vec<String>) {
    let mut text = String::with_capacity(source.len());
    let mut warnings = Vec::new();
    for (number, line) in source.lines().enumerate() {
        let mut words = line.split_whitespace();
        let key = words.next();
        let values: Vec<&str> = words.collect();
        match key {
            Some("newmtl") if values.is_empty() => {
                text.push_str("newmtl ");
                text.push_str(UNNAMED_MATERIAL);
            }
            Some(k @ ("Ka" | "Kd" | "Ks" | "Ke" | "Tf")) => {
                let numbers: Option<Vec<f32>> = values.iter().map(|v| v.parse().ok()).collect();
                match numbers.as_deref() {
                    Some(&[v]) => text.push_str(&format!("{k} {v} {v} {v}")),
                    Some(&[_, _, _]) => text.push_str(line),
                    _ => {
                        warnings.push(format!(
                            "line {}: '{}' is not a colour; the default is used",
                            number + 1,
                            line.trim()
                        ));
                        continue;
                    }
                }
            }
            Some(k @ ("d" | "Tr" | "Ns" | "Ni" | "illum")) => {
                if values.len() != 1 || values[0].parse::<f32>().is_err() {
                    warnings.push(format!(
                        "line {}: '{}' is not a {k} value; the default is used",
                        number + 1,
                        line.trim()
                    ));
                    continue;
                }
                text.push_str(line);
            }
            _ => text.push_str(line),
        }
        text.push('\n');
    }
    (text, warnings)
}

/// The file name in a texture statement's value, without options such as `-s 1 1 1` or
/// `-bm 0.5` (the name is what follows the last option's arguments; names may hold spaces).
pub(crate) fn texture_file_name(value: &str) -> &str {
    let value = value.trim();
    if !value.starts_with('-') {
        return value;
    }
    // Options take numeric arguments (or on/off); the name is the first word after them that
    // is neither an option nor an argument.
    let mut rest = value;
    loop {
        let trimmed = rest.trim_start();
        let word_end = trimmed.find(char::is_whitespace).unwrap_or(trimmed.len());
        let word = &trimmed[..word_end];
        let is_argument =
            word.starts_with('-') || word.parse::<f32>().is_ok() || matches!(word, "on" | "off");
        if !is_argument || word_end == trimmed.len() {
            return trimmed;
        }
        rest = &trimmed[word_end..];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn latin1_and_utf8() {
        assert_eq!(text("äb".as_bytes()), "äb");
        assert_eq!(text(b"caf\xe9"), "café");
    }

    #[test]
    fn obj_lines_and_points_are_taken_out() {
        let p = patch_obj("v 0 0 0\nl 1 2 3\np 1\nusemtl\nf 1 2 3\n");
        assert_eq!(p.lines, 1);
        assert_eq!(p.points, 1);
        assert_eq!(
            p.text,
            format!("v 0 0 0\nusemtl {UNNAMED_MATERIAL}\nf 1 2 3\n")
        );
    }

    #[test]
    fn mtl_colours_are_widened_or_dropped() {
        let (text, warnings) = patch_mtl("newmtl\nKd 0.8\nKa 1 1\nKs 1 2 3\nd x\n");
        assert_eq!(
            text,
            format!("newmtl {UNNAMED_MATERIAL}\nKd 0.8 0.8 0.8\nKs 1 2 3\n")
        );
        assert_eq!(warnings.len(), 2);
        assert!(warnings[0].starts_with("line 3"), "{warnings:?}");
    }

    #[test]
    fn texture_options_are_skipped() {
        assert_eq!(texture_file_name("wood.png"), "wood.png");
        assert_eq!(texture_file_name("my wood.png"), "my wood.png");
        assert_eq!(texture_file_name("-s 1 1 1 wood.png"), "wood.png");
        assert_eq!(
            texture_file_name("-clamp on -bm 0.5 my wood.png"),
            "my wood.png"
        );
    }
}
