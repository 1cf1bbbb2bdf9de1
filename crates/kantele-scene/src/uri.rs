//! URIs in glTF files: `data:` URIs and relative (percent-encoded) file references, read under
//! the load's [`ReadPolicy`] and [`Budget`].

use std::path::{Path, PathBuf};

use crate::budget::Budget;
use crate::read_policy::ReadPolicy;

/// Reads the data an URI refers to: a base64 `data:` URI, or a file relative to the scene file
/// (`file://` URIs too), confined by `policy`. The error says what is wrong, without the file
/// name of the scene.
pub(crate) fn read_uri(
    scene: &Path,
    uri: &str,
    policy: &ReadPolicy,
    budget: &mut Budget,
) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((_, payload)) = rest.split_once(";base64,") else {
            return Err("only base64 data URIs are supported".to_string());
        };
        budget.charge(payload.len() as u64 / 4 * 3 + 3, 1, "decoding a data URI")?;
        return decode_base64(payload)
            .ok_or_else(|| "the data URI is not valid base64".to_string());
    }
    let file: PathBuf = if let Some(rest) = uri.strip_prefix("file://") {
        PathBuf::from(percent_decode(rest))
    } else if uri.contains(':') && !looks_like_windows_path(uri) {
        return Err(format!(
            "unsupported URI '{uri}' (only relative files and data URIs)"
        ));
    } else {
        scene
            .parent()
            .unwrap_or(Path::new(""))
            .join(percent_decode(uri))
    };
    policy.read(&file, budget)
}

pub(crate) fn looks_like_windows_path(uri: &str) -> bool {
    let b = uri.as_bytes();
    b.len() > 2 && b[0].is_ascii_alphabetic() && b[1] == b':' && (b[2] == b'/' || b[2] == b'\\')
}

/// Decodes `%XX` escapes (URIs in glTF are percent-encoded); malformed escapes stay as they are.
pub(crate) fn percent_decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = std::str::from_utf8(&bytes[i + 1..i + 3])
                .ok()
                .and_then(|h| u8::from_str_radix(h, 16).ok());
            if let Some(byte) = hex {
                out.push(byte);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Standard base64 (RFC 4648, padding optional, whitespace ignored); `None` on a bad character.
pub(crate) fn decode_base64(s: &str) -> Option<Vec<u8>> {
    fn value(c: u8) -> Option<u32> {
        Some(match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return None,
        } as u32)
    }
    let mut out = Vec::with_capacity(s.len() / 4 * 3);
    let mut acc = 0u32;
    let mut bits = 0;
    for c in s.bytes() {
        if c == b'=' {
            break;
        }
        if c.is_ascii_whitespace() {
            continue;
        }
        acc = (acc << 6) | value(c)?;
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trip() {
        assert_eq!(decode_base64("aGVsbG8=").unwrap(), b"hello");
        assert_eq!(decode_base64("aGVsbG8").unwrap(), b"hello");
        assert_eq!(decode_base64("AAECAwQF").unwrap(), vec![0, 1, 2, 3, 4, 5]);
        assert_eq!(decode_base64("").unwrap(), Vec::<u8>::new());
        assert!(decode_base64("a*b").is_none());
    }

    #[test]
    fn percent_decoding() {
        assert_eq!(percent_decode("my%20file.png"), "my file.png");
        assert_eq!(percent_decode("100%"), "100%");
        assert_eq!(percent_decode("%zz%4"), "%zz%4");
        assert_eq!(percent_decode("%C3%A4.bin"), "ä.bin");
    }
}
