//! MTL text read into [`MtlMaterial`]s: the statements that the loader maps onto glTF's
//! material model (`obj_material`), with their texture statements (`mtl_texture`). Keywords
//! are matched in any case. Statements that have no place in that model are named in
//! [`MtlLibrary::ignored`] (the ambient colour `Ka`, `Ni`, `illum` and `Tf`, which every
//! exporter writes, silently); a malformed value is skipped with a warning naming its line,
//! and the material keeps its default for it.

use glam::Vec3;

use crate::budget::Budget;
use crate::mtl_texture::{parse_texture, TextureRef};

/// Bytes charged to the budget for each material read, for what the loader keeps of it (this
/// record, `tobj`'s and the scene's material).
pub(crate) const BYTES_PER_MATERIAL: u64 = 4096;

/// The texture statements of a material that the loader uses.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct MtlMaps {
    /// `map_Kd`.
    pub diffuse: Option<TextureRef>,
    /// `map_Ks`.
    pub specular: Option<TextureRef>,
    /// `map_Ke`.
    pub emissive: Option<TextureRef>,
    /// `norm`, else `map_Bump` / `bump`.
    pub normal: Option<TextureRef>,
    /// `map_Pr`.
    pub roughness: Option<TextureRef>,
    /// `map_Pm`.
    pub metallic: Option<TextureRef>,
    /// `map_Ns`.
    pub shininess: Option<TextureRef>,
    /// `map_d`.
    pub alpha: Option<TextureRef>,
}

/// One `newmtl` material, as the file states it (`None`: not stated).
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct MtlMaterial {
    /// Its name (may be empty).
    pub name: String,
    /// `Kd`.
    pub diffuse: Option<Vec3>,
    /// `Ks`.
    pub specular: Option<Vec3>,
    /// `Ke`.
    pub emissive: Option<Vec3>,
    /// `Ns`.
    pub shininess: Option<f32>,
    /// `d`.
    pub dissolve: Option<f32>,
    /// `Tr` (1 − `d`).
    pub transparency: Option<f32>,
    /// `Pr`.
    pub roughness: Option<f32>,
    /// `Pm`.
    pub metallic: Option<f32>,
    /// `Pc`.
    pub clearcoat: Option<f32>,
    /// `Pcr`.
    pub clearcoat_roughness: Option<f32>,
    /// Its texture statements.
    pub maps: MtlMaps,
    /// Whether `normal` came from `norm` (which `map_Bump` does not replace).
    norm_given: bool,
}

/// What an MTL file holds.
#[derive(Debug, Default)]
pub(crate) struct MtlLibrary {
    /// Its materials, in file order.
    pub materials: Vec<MtlMaterial>,
    /// One message per line that could not be read (starting `line N:`).
    pub warnings: Vec<String>,
    /// The statements used that the loader does not draw (`MTL map_Ka`, ...), once each.
    pub ignored: Vec<String>,
}

/// Reads MTL text (decoded and joined, see `obj_text`), charging each material to `budget`.
pub(crate) fn parse_mtl(source: &str, budget: &mut Budget) -> Result<MtlLibrary, String> {
    let mut library = MtlLibrary::default();
    let mut current: Option<MtlMaterial> = None;
    for (index, line) in source.lines().enumerate() {
        let line = line.trim();
        let Some(keyword) = line.split_whitespace().next() else {
            continue;
        };
        let rest = line[keyword.len()..].trim();
        let lower = keyword.to_ascii_lowercase();
        if lower == "newmtl" {
            budget.charge(
                1,
                BYTES_PER_MATERIAL + rest.len() as u64,
                "the MTL materials",
            )?;
            library.materials.extend(current.take());
            current = Some(MtlMaterial {
                name: rest.to_string(),
                ..MtlMaterial::default()
            });
            continue;
        }
        // Statements before the first `newmtl` belong to no material.
        let Some(m) = current.as_mut() else {
            continue;
        };
        let mut warn = |what: String| {
            library.warnings.push(format!("line {}: {what}", index + 1));
        };
        match lower.as_str() {
            "kd" | "ks" | "ke" => match colour(rest) {
                Some(c) => match lower.as_str() {
                    "kd" => m.diffuse = Some(c),
                    "ks" => m.specular = Some(c),
                    _ => m.emissive = Some(c),
                },
                None => warn(format!("'{line}' is not a colour; the default is used")),
            },
            "ns" | "d" | "tr" | "pr" | "pm" | "pc" | "pcr" => {
                let mut value = rest;
                if lower == "d" {
                    if let Some(after) = strip_word(rest, "-halo") {
                        ignore(&mut library.ignored, "MTL d -halo");
                        value = after;
                    }
                }
                let Some(v) = single_number(value) else {
                    warn(format!(
                        "'{line}' is not a {keyword} value; the default is used"
                    ));
                    continue;
                };
                let slot = match lower.as_str() {
                    "ns" => &mut m.shininess,
                    "d" => &mut m.dissolve,
                    "tr" => &mut m.transparency,
                    "pr" => &mut m.roughness,
                    "pm" => &mut m.metallic,
                    "pc" => &mut m.clearcoat,
                    _ => &mut m.clearcoat_roughness,
                };
                *slot = Some(v);
            }
            "map_kd" | "map_ks" | "map_ke" | "norm" | "map_bump" | "bump" | "map_pr" | "map_pm"
            | "map_ns" | "map_d" => {
                let (texture, warnings) = parse_texture(rest);
                for w in warnings {
                    warn(format!("{keyword}: {w}"));
                }
                let Some(texture) = texture else {
                    continue;
                };
                let maps = &mut m.maps;
                let slot = match lower.as_str() {
                    "map_kd" => &mut maps.diffuse,
                    "map_ks" => &mut maps.specular,
                    "map_ke" => &mut maps.emissive,
                    "norm" => {
                        m.norm_given = true;
                        &mut maps.normal
                    }
                    "map_bump" | "bump" if m.norm_given => continue,
                    "map_bump" | "bump" => &mut maps.normal,
                    "map_pr" => &mut maps.roughness,
                    "map_pm" => &mut maps.metallic,
                    "map_ns" => &mut maps.shininess,
                    _ => &mut maps.alpha,
                };
                *slot = Some(texture);
            }
            "map_ka" | "disp" | "decal" | "refl" | "map_refl" | "map_ps" | "map_pc" | "map_pcr"
            | "map_aniso" | "map_anisor" | "ps" | "aniso" | "anisor" => {
                ignore(&mut library.ignored, &format!("MTL {keyword}"));
            }
            // `Ka`, `Ni`, `illum`, `Tf`, `sharpness` and unknown statements.
            _ => {}
        }
    }
    library.materials.extend(current);
    Ok(library)
}

/// Records an ignored statement once.
fn ignore(ignored: &mut Vec<String>, what: &str) {
    if !ignored.iter().any(|i| i == what) {
        ignored.push(what.to_string());
    }
}

/// `text` after its first word when that word is `word` (any case).
fn strip_word<'a>(text: &'a str, word: &str) -> Option<&'a str> {
    let text = text.trim_start();
    let first = text.split_whitespace().next()?;
    first
        .eq_ignore_ascii_case(word)
        .then(|| text[first.len()..].trim_start())
}

/// One finite number and nothing else.
fn single_number(text: &str) -> Option<f32> {
    let mut words = text.split_whitespace();
    let value = words.next()?.parse::<f32>().ok()?;
    (words.next().is_none() && value.is_finite()).then_some(value)
}

/// A colour of one value (grey) or three, finite.
fn colour(text: &str) -> Option<Vec3> {
    let values: Option<Vec<f32>> = text
        .split_whitespace()
        .map(|w| w.parse::<f32>().ok().filter(|v| v.is_finite()))
        .collect();
    match *values?.as_slice() {
        [v] => Some(Vec3::splat(v)),
        [r, g, b] => Some(Vec3::new(r, g, b)),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> MtlLibrary {
        parse_mtl(text, &mut Budget::new(1 << 20)).expect("within the budget")
    }

    #[test]
    fn values_maps_and_malformed_lines() {
        let library = parse(
            "Kd 1 0 0\nnewmtl\nKD 0.8\nKa 1 1\nks 1 2 3\nd x\nnewmtl b c\nTr 0.25\nNs 250\n\
             Pr 0.5\nPm 1\nPc 0.5\nPcr 0.1\nKe 1 1 1\nd -halo 0.5\n",
        );
        assert_eq!(library.materials.len(), 2);
        let a = &library.materials[0];
        assert_eq!(a.name, "");
        assert_eq!(a.diffuse, Some(Vec3::splat(0.8)));
        assert_eq!(a.specular, Some(Vec3::new(1.0, 2.0, 3.0)));
        assert_eq!(a.dissolve, None);
        let b = &library.materials[1];
        assert_eq!(b.name, "b c");
        assert_eq!(
            (b.transparency, b.shininess, b.roughness, b.metallic),
            (Some(0.25), Some(250.0), Some(0.5), Some(1.0))
        );
        assert_eq!((b.clearcoat, b.clearcoat_roughness), (Some(0.5), Some(0.1)));
        assert_eq!((b.emissive, b.dissolve), (Some(Vec3::ONE), Some(0.5)));
        // `Ka 1 1` is not read at all (ambient has no place); `d x` is malformed.
        assert_eq!(library.warnings.len(), 1, "{:?}", library.warnings);
        assert!(library.warnings[0].starts_with("line 6:"));
        assert_eq!(library.ignored, ["MTL d -halo"]);
    }

    #[test]
    fn texture_statements() {
        let library = parse(
            "newmtl m\nmap_Kd -s 2 2 a b.png\nnorm n.png\nmap_Bump bump.png\nmap_Pr r.png\n\
             map_Pm -imfchan b m.png\nmap_Ns ns.png\nmap_d -bm 2\nmap_Ka ka.png\ndisp d.png\n\
             map_Ke e.png\nmap_Ks s.png\n",
        );
        let maps = &library.materials[0].maps;
        let file = |t: &Option<TextureRef>| t.as_ref().map(|t| t.file.clone());
        assert_eq!(file(&maps.diffuse).as_deref(), Some("a b.png"));
        assert_eq!(file(&maps.normal).as_deref(), Some("n.png"));
        assert_eq!(file(&maps.roughness).as_deref(), Some("r.png"));
        assert_eq!(file(&maps.metallic).as_deref(), Some("m.png"));
        assert_eq!(file(&maps.shininess).as_deref(), Some("ns.png"));
        assert_eq!(file(&maps.emissive).as_deref(), Some("e.png"));
        assert_eq!(file(&maps.specular).as_deref(), Some("s.png"));
        assert_eq!(maps.alpha, None);
        assert_eq!(library.ignored, ["MTL map_Ka", "MTL disp"]);
        assert_eq!(library.warnings.len(), 1, "{:?}", library.warnings);
        assert!(library.warnings[0].starts_with("line 8: map_d: no texture file name"));
    }

    #[test]
    fn materials_are_charged_to_the_budget() {
        let text = "newmtl a\n".repeat(100);
        let e = parse_mtl(&text, &mut Budget::new(50 * BYTES_PER_MATERIAL)).unwrap_err();
        assert!(e.contains("memory budget"), "{e}");
    }
}
