//! OBJ and MTL text as the readers take it, and OBJ text made safe for `tobj`, which fails on or
//! misreads some valid input.
//!
//! - Bytes become text: UTF-16 (little- or big-endian) when they start with its byte-order
//!   mark, otherwise UTF-8 when valid (a UTF-8 byte-order mark is dropped), otherwise Latin-1.
//! - A line ending in `\` continues on the next line (comment lines excepted, whose `\` is
//!   often the end of a Windows folder name); a `\` on the last line is dropped.
//! - `l` / `p` lines (lines and points) are taken out instead of being read as faces
//!   (`obj_wide` reads them), an empty `usemtl` names the unnamed material, `usemtl` and
//!   `mtllib` take their name after any run of blanks, and when only some `v` lines carry a
//!   colour the others get white (`tobj` would misalign or refuse them).

/// The name given to materials declared with an empty `newmtl` (and used by an empty
/// `usemtl`); reported as an empty name.
pub(crate) const UNNAMED_MATERIAL: &str = "kantele-unnamed-material";

/// Text from bytes (decoded as the module documentation says), with continued lines joined.
pub(crate) fn text(bytes: &[u8]) -> String {
    join_continued_lines(decode(bytes))
}

/// Decodes UTF-16 with a byte-order mark, UTF-8, or else Latin-1 (every byte one character).
fn decode(bytes: &[u8]) -> String {
    match bytes {
        [0xff, 0xfe, rest @ ..] => utf16(rest, u16::from_le_bytes),
        [0xfe, 0xff, rest @ ..] => utf16(rest, u16::from_be_bytes),
        _ => {
            let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
            match std::str::from_utf8(bytes) {
                Ok(s) => s.to_string(),
                Err(_) => bytes.iter().map(|&b| b as char).collect(),
            }
        }
    }
}

/// UTF-16 code units read by `unit`; unpaired surrogates become U+FFFD and an odd last byte
/// is dropped.
fn utf16(bytes: &[u8], unit: fn([u8; 2]) -> u16) -> String {
    let units = bytes.chunks_exact(2).map(|p| unit([p[0], p[1]]));
    let mut out = String::with_capacity(bytes.len() / 2);
    out.extend(char::decode_utf16(units).map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER)));
    out
}

/// Whether a line continues on the next one: it ends in `\` (before trailing blanks) and is
/// not a comment.
fn continues(line: &str) -> bool {
    line.trim_end().ends_with('\\') && !line.trim_start().starts_with('#')
}

/// Joins each line ending in `\` with the next one, the `\` becoming a space.
fn join_continued_lines(text: String) -> String {
    if !text.lines().any(continues) {
        return text;
    }
    let mut out = String::with_capacity(text.len());
    for line in text.lines() {
        if continues(line) {
            let kept = line.trim_end();
            out.push_str(&kept[..kept.len() - 1]);
            out.push(' ');
        } else {
            out.push_str(line);
            out.push('\n');
        }
    }
    out
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
    /// Number of `f` (face) statements.
    pub faces: usize,
    /// Number of `v` (vertex) statements.
    pub vertices: usize,
}

/// Patches OBJ text (already decoded and joined) for `tobj`.
pub(crate) fn patch_obj(source: &str) -> ObjPatch {
    let vertex_values = |line: &str| {
        let mut words = line.split_whitespace();
        (words.next() == Some("v")).then(|| words.count())
    };
    let (mut vertices, mut coloured) = (0, 0);
    for line in source.lines() {
        match vertex_values(line) {
            Some(6) => (vertices, coloured) = (vertices + 1, coloured + 1),
            Some(_) => vertices += 1,
            None => {}
        }
    }
    let fill_colours = coloured > 0 && coloured < vertices;
    let mut out = ObjPatch {
        text: String::with_capacity(source.len()),
        vertices,
        ..ObjPatch::default()
    };
    for line in source.lines() {
        let trimmed = line.trim_start();
        let mut words = trimmed.split_whitespace();
        match words.next() {
            Some("l") => out.lines += 1,
            Some("p") => out.points += 1,
            Some(keyword @ ("usemtl" | "mtllib")) => {
                let name = trimmed[keyword.len()..].trim();
                let name = if name.is_empty() && keyword == "usemtl" {
                    UNNAMED_MATERIAL
                } else {
                    name
                };
                out.text.push_str(keyword);
                out.text.push(' ');
                out.text.push_str(name);
                out.text.push('\n');
            }
            Some("v") if fill_colours => {
                out.text.push_str(&white_vertex(line));
                out.text.push('\n');
            }
            Some(keyword) => {
                if keyword == "f" {
                    out.faces += 1;
                }
                out.text.push_str(line);
                out.text.push('\n');
            }
            None => out.text.push('\n'),
        }
    }
    out
}

/// A `v` line with a white colour when it has none: `x y z` gains `1 1 1`, `x y z w` becomes
/// `x/w y/w z/w 1 1 1`; other lines are kept for `tobj` to judge.
fn white_vertex(line: &str) -> String {
    let values: Vec<&str> = line.split_whitespace().skip(1).collect();
    match values.as_slice() {
        [_, _, _] => format!("{} 1 1 1", line.trim_end()),
        [x, y, z, w] => {
            let numbers: Option<Vec<f32>> = [x, y, z, w].iter().map(|v| v.parse().ok()).collect();
            match numbers.as_deref() {
                Some(&[x, y, z, w]) if w != 0.0 => {
                    format!("v {} {} {} 1 1 1", x / w, y / w, z / w)
                }
                _ => line.to_string(),
            }
        }
        _ => line.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn latin1_utf8_and_utf16() {
        assert_eq!(text("äb".as_bytes()), "äb");
        assert_eq!(text(b"caf\xe9"), "café");
        assert_eq!(text(b"\xef\xbb\xbfv 1"), "v 1");
        let le: Vec<u8> = [0xfeff_u16, 'v' as u16, ' ' as u16, 0xe4]
            .iter()
            .flat_map(|u| u.to_le_bytes())
            .collect();
        assert_eq!(text(&le), "v ä");
        let mut be: Vec<u8> = [0xfeff_u16, 'f' as u16, 0xd800]
            .iter()
            .flat_map(|u| u.to_be_bytes())
            .collect();
        be.push(b'x');
        assert_eq!(text(&be), "f\u{fffd}");
    }

    #[test]
    fn continued_lines_are_joined() {
        assert_eq!(text(b"f 1 2 \\\n3\nv 1\n"), "f 1 2  3\nv 1\n");
        assert_eq!(text(b"f 1 \\  \r\n 2\\\n3"), "f 1   2 3\n");
        // A comment's trailing backslash does not swallow the next line; one at the very end
        // of the file is dropped.
        assert_eq!(
            text(b"# C:\\models\\\nv 1\nf \\"),
            "# C:\\models\\\nv 1\nf  "
        );
        assert_eq!(text(b"\\\n\\\n\\"), "   ");
    }

    #[test]
    fn obj_lines_and_points_are_taken_out() {
        let p = patch_obj("v 0 0 0\nl 1 2 3\np 1\nusemtl\nf 1 2 3\nmtllib\ta b.mtl \n");
        assert_eq!((p.lines, p.points, p.faces, p.vertices), (1, 1, 1, 1));
        assert_eq!(
            p.text,
            format!("v 0 0 0\nusemtl {UNNAMED_MATERIAL}\nf 1 2 3\nmtllib a b.mtl\n")
        );
    }

    #[test]
    fn vertices_without_a_colour_get_white_when_others_have_one() {
        let p = patch_obj("v 0 0 0 1 0 0\nv 1 0 0\nv 2 4 6 2\nv 1 1\n");
        assert_eq!(
            p.text,
            "v 0 0 0 1 0 0\nv 1 0 0 1 1 1\nv 1 2 3 1 1 1\nv 1 1\n"
        );
        let p = patch_obj("v 0 0 0\nv 1 0 0\n");
        assert_eq!(p.text, "v 0 0 0\nv 1 0 0\n");
    }
}
