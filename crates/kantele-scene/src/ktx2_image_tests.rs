//! Tests of the KTX2 decoder: a real UASTC file, generated ETC1S and Zstandard UASTC files of a
//! known picture, uncompressed files written here, and broken or hostile files.

use super::*;

const ETC1S: &[u8] = include_bytes!("../tests/data/ktx2/quadrants-etc1s.ktx2");
const ETC1S_ALPHA: &[u8] = include_bytes!("../tests/data/ktx2/quadrants-etc1s-alpha.ktx2");
const UASTC_ZSTD: &[u8] = include_bytes!("../tests/data/ktx2/quadrants-uastc-zstd.ktx2");

/// Source colours of the quadrant picture (tests/data/ktx2/README.md): top left, top right,
/// bottom left, bottom right.
const QUADRANTS: [[u8; 3]; 4] = [[200, 40, 40], [40, 160, 60], [30, 60, 200], [230, 220, 90]];

fn decode(bytes: &[u8], color_space: ColorSpace) -> Result<Texture, String> {
    let mut budget = Budget::new(crate::DEFAULT_MAX_MEMORY);
    decode_ktx2(bytes, color_space, &mut budget).map_err(|e| match e {
        ImageError::Budget(m) | ImageError::Decode(m) => m,
    })
}

/// The RGBA bytes of level 0's texel at (`x`, `y`).
fn texel(texture: &Texture, x: u32, y: u32) -> [u8; 4] {
    texture
        .level(0)
        .expect("level 0")
        .packed(x, y)
        .to_le_bytes()
}

/// The texels at the centres of the four quadrants of a 32 × 32 picture.
fn quadrant_centres(texture: &Texture) -> [[u8; 4]; 4] {
    [(8, 8), (24, 8), (8, 24), (24, 24)].map(|(x, y)| texel(texture, x, y))
}

/// A one-level KTX2 file of an uncompressed `format`, with `texels` as its level 0 and, when
/// given, a `KTXorientation` value.
fn plain_ktx2(
    format: Format,
    width: u32,
    height: u32,
    texels: &[u8],
    orientation: Option<&str>,
) -> Vec<u8> {
    plain_ktx2_levels(format, width, height, &[texels], orientation)
}

/// A KTX2 file of an uncompressed `format` with `levels` as its levels, level 0 first (stored
/// in the file smallest first, as the specification orders them) and, when given, a
/// `KTXorientation` value.
fn plain_ktx2_levels(
    format: Format,
    width: u32,
    height: u32,
    levels: &[&[u8]],
    orientation: Option<&str>,
) -> Vec<u8> {
    let (dfd, _) = ktx2::dfd::Basic::from_format(format).expect("a DFD for the format");
    let dfd = ktx2::dfd::Block::Basic(dfd).to_vec();
    let mut kvd = Vec::new();
    if let Some(o) = orientation {
        let entry = [b"KTXorientation\0".as_slice(), o.as_bytes(), b"\0"].concat();
        kvd.extend_from_slice(&(entry.len() as u32).to_le_bytes());
        kvd.extend_from_slice(&entry);
        while kvd.len() % 4 != 0 {
            kvd.push(0);
        }
    }
    let dfd_offset = 80 + 24 * levels.len();
    let dfd_length = 4 + dfd.len();
    let kvd_offset = dfd_offset + dfd_length;
    let data_offset = kvd_offset + kvd.len();
    let mut out = KTX2_MAGIC.to_vec();
    let level_count = levels.len() as u32;
    for word in [format.value(), 1, width, height, 0, 0, 1, level_count, 0] {
        out.extend_from_slice(&word.to_le_bytes());
    }
    let kvd_offset_field = if kvd.is_empty() { 0 } else { kvd_offset };
    for word in [dfd_offset, dfd_length, kvd_offset_field, kvd.len()] {
        out.extend_from_slice(&(word as u32).to_le_bytes());
    }
    // No supercompression global data.
    out.extend_from_slice(&[0; 16]);
    // The level index, level 0 first; the data, smallest level first.
    let mut offset = data_offset + levels.iter().map(|l| l.len()).sum::<usize>();
    for level in levels {
        offset -= level.len();
        for long in [offset, level.len(), level.len()] {
            out.extend_from_slice(&(long as u64).to_le_bytes());
        }
    }
    out.extend_from_slice(&(dfd_length as u32).to_le_bytes());
    out.extend_from_slice(&dfd);
    out.extend_from_slice(&kvd);
    for level in levels.iter().rev() {
        out.extend_from_slice(level);
    }
    out
}

/// The quadrant picture as 32 × 32 RGBA8 texels (alpha as in the README).
fn quadrant_texels() -> Vec<u8> {
    let mut rgba = Vec::new();
    for y in 0..32 {
        for x in 0..32 {
            let [r, g, b] = QUADRANTS[(y / 16) * 2 + x / 16];
            rgba.extend_from_slice(&[r, g, b, if y < 16 { 255 } else { 128 }]);
        }
    }
    rgba
}

#[test]
fn real_uastc_file_decodes_to_its_picture() {
    let Some(dir) = kantele_testkit::shared_dir("realworld") else {
        return;
    };
    let bytes = std::fs::read(dir.join("ktx2/uastc-256.ktx2")).expect("read uastc-256.ktx2");
    assert_eq!(ktx2_size(&bytes).unwrap(), (256, 256));
    let texture = decode(&bytes, ColorSpace::Srgb).unwrap();
    assert_eq!((texture.width(), texture.height()), (256, 256));
    // The file has one level; the texture builds the rest of the chain.
    assert_eq!(texture.level_count(), 9);
    // A painted landscape in horizontal bands: pale sky at the top, an ochre band, dark
    // ground, an orange stripe near the bottom. Texels as the reference C++ transcoder gives
    // them (RGBA32 output of basisu_transcoder).
    for ((x, y), expected) in [
        ((0, 0), [215, 224, 186, 255]),
        ((128, 10), [199, 213, 174, 255]),
        ((128, 70), [144, 122, 72, 255]),
        ((128, 100), [71, 49, 30, 255]),
        ((128, 150), [35, 38, 25, 255]),
        ((20, 205), [112, 79, 25, 255]),
        ((250, 250), [215, 215, 180, 255]),
    ] {
        assert_eq!(texel(&texture, x, y), expected, "texel ({x}, {y})");
    }
    // The means of the whole picture (reference: 105.19, 100.79, 72.47, 255).
    let level = texture.level(0).unwrap();
    let mut sums = [0u64; 4];
    for &t in level.texels {
        for (s, b) in sums.iter_mut().zip(t.to_le_bytes()) {
            *s += u64::from(b);
        }
    }
    let means = sums.map(|s| s as f64 / (256.0 * 256.0));
    for (mean, expected) in means.iter().zip([105.19, 100.79, 72.47, 255.0]) {
        assert!((mean - expected).abs() < 0.01, "means {means:?}");
    }
    // The file declares sRGB texels: no note for a colour texture, one for a data texture.
    assert_eq!(color_space_note(&bytes, ColorSpace::Srgb), None);
    let note = color_space_note(&bytes, ColorSpace::Linear).unwrap();
    assert!(note.contains("declares sRGB"), "{note}");
}

#[test]
fn etc1s_decodes_to_the_reference_texels() {
    let texture = decode(ETC1S, ColorSpace::Srgb).unwrap();
    assert_eq!(
        (texture.width(), texture.height(), texture.level_count()),
        (32, 32, 6)
    );
    let expected = [
        [198, 41, 41, 255],
        [38, 161, 62, 255],
        [28, 61, 201, 255],
        [229, 220, 88, 255],
    ];
    assert_eq!(quadrant_centres(&texture), expected);
    // The file holds all six levels: the texture keeps the transcoder's, not its own averages.
    let transcoder = basisu::Transcoder::new(ETC1S).unwrap();
    for (index, level) in texture.levels().enumerate() {
        let rgba = transcoder
            .transcode(
                index as u32,
                basisu::TargetFormat::Rgba32,
                basisu::DecodeFlags::NONE,
            )
            .unwrap();
        let stored: Vec<u8> = level.texels.iter().flat_map(|t| t.to_le_bytes()).collect();
        assert_eq!(stored, rgba, "level {index}");
    }
    // ETC1S is lossy, but flat quadrants stay within a few units of their source colour.
    for (got, source) in expected.iter().zip(QUADRANTS) {
        for k in 0..3 {
            assert!(got[k].abs_diff(source[k]) <= 3, "{got:?} vs {source:?}");
        }
    }
}

#[test]
fn etc1s_with_alpha_keeps_its_alpha() {
    let texture = decode(ETC1S_ALPHA, ColorSpace::Srgb).unwrap();
    let centres = quadrant_centres(&texture);
    assert_eq!(centres.map(|t| t[3]), [255, 255, 128, 128]);
    assert_eq!(centres[2], [28, 61, 201, 128]);
}

#[test]
fn zstd_uastc_decodes_exactly() {
    assert_eq!(
        ktx2::Reader::new(UASTC_ZSTD)
            .unwrap()
            .header()
            .supercompression_scheme,
        Some(SupercompressionScheme::Zstandard)
    );
    let texture = decode(UASTC_ZSTD, ColorSpace::Linear).unwrap();
    let alpha = [255, 255, 128, 128];
    let expected: Vec<[u8; 4]> = QUADRANTS
        .iter()
        .zip(alpha)
        .map(|(&[r, g, b], a)| [r, g, b, a])
        .collect();
    assert_eq!(quadrant_centres(&texture).to_vec(), expected);
    // Linear in the file and in use: no note.
    assert_eq!(color_space_note(UASTC_ZSTD, ColorSpace::Linear), None);
    assert!(color_space_note(UASTC_ZSTD, ColorSpace::Srgb).is_some());
}

#[test]
fn uncompressed_rgba_and_rgb_decode_as_stored() {
    let rgba = quadrant_texels();
    let file = plain_ktx2(Format::R8G8B8A8_SRGB, 32, 32, &rgba, None);
    let texture = decode(&file, ColorSpace::Srgb).unwrap();
    assert_eq!(texture.level(0).unwrap().texels.len(), 32 * 32);
    assert_eq!(texel(&texture, 24, 24), [230, 220, 90, 128]);
    assert_eq!(texel(&texture, 8, 8), [200, 40, 40, 255]);

    let rgb: Vec<u8> = rgba
        .chunks_exact(4)
        .flat_map(|t| [t[0], t[1], t[2]])
        .collect();
    let file = plain_ktx2(Format::R8G8B8_UNORM, 32, 32, &rgb, None);
    let texture = decode(&file, ColorSpace::Linear).unwrap();
    assert_eq!(texel(&texture, 24, 8), [40, 160, 60, 255]);
    assert_eq!(texel(&texture, 8, 24), [30, 60, 200, 255]);
}

/// `width` × `height` RGBA8 texels all of `colour`.
fn flat(width: u32, height: u32, colour: [u8; 4]) -> Vec<u8> {
    colour.repeat(width as usize * height as usize)
}

/// Every texel of level `index`, as RGBA bytes.
fn level_texels(texture: &Texture, index: usize) -> Vec<[u8; 4]> {
    let level = texture.level(index).expect("level");
    level.texels.iter().map(|t| t.to_le_bytes()).collect()
}

const RED: [u8; 4] = [200, 0, 0, 255];
const GREEN: [u8; 4] = [0, 180, 0, 255];
const BLUE: [u8; 4] = [0, 0, 160, 128];

#[test]
fn a_complete_mip_chain_is_taken_from_the_file() {
    let (l0, l1, l2) = (flat(4, 2, RED), flat(2, 1, GREEN), flat(1, 1, BLUE));
    let file = plain_ktx2_levels(Format::R8G8B8A8_SRGB, 4, 2, &[&l0, &l1, &l2], None);
    let texture = decode(&file, ColorSpace::Srgb).unwrap();
    assert_eq!(texture.level_count(), 3);
    // The file's levels as they are, not averages of level 0 (which would stay red).
    assert_eq!(level_texels(&texture, 0), vec![RED; 8]);
    assert_eq!(level_texels(&texture, 1), vec![GREEN; 2]);
    assert_eq!(level_texels(&texture, 2), vec![BLUE]);
    // RGB with its levels, bottom-up: each level's rows are turned over.
    let rgb = |rgba: &[u8]| -> Vec<u8> {
        rgba.chunks_exact(4)
            .flat_map(|t| [t[0], t[1], t[2]])
            .collect()
    };
    let mut l0 = flat(4, 2, RED);
    l0[..16].copy_from_slice(&flat(4, 1, GREEN));
    let file = plain_ktx2_levels(
        Format::R8G8B8_UNORM,
        4,
        2,
        &[&rgb(&l0), &rgb(&l1), &rgb(&l2)],
        Some("ru"),
    );
    let texture = decode(&file, ColorSpace::Linear).unwrap();
    assert_eq!(texel(&texture, 0, 0), RED);
    assert_eq!(texel(&texture, 0, 1), GREEN);
    assert_eq!(level_texels(&texture, 1), vec![GREEN; 2]);
    assert_eq!(level_texels(&texture, 2), vec![[0, 0, 160, 255]]);
}

#[test]
fn an_incomplete_or_wrongly_sized_chain_falls_back_to_level_0() {
    let (l0, l1, l2) = (flat(4, 2, RED), flat(2, 1, GREEN), flat(1, 1, BLUE));
    let built = |texture: &Texture| {
        assert_eq!(texture.level_count(), 3);
        assert_eq!(level_texels(texture, 0), vec![RED; 8]);
        // Built from level 0: red again.
        assert_eq!(level_texels(texture, 1), vec![RED; 2]);
        assert_eq!(level_texels(texture, 2), vec![RED]);
    };
    // Two levels of three.
    let file = plain_ktx2_levels(Format::R8G8B8A8_SRGB, 4, 2, &[&l0, &l1], None);
    built(&decode(&file, ColorSpace::Srgb).unwrap());
    // Level 1 of the wrong size.
    let file = plain_ktx2_levels(Format::R8G8B8A8_SRGB, 4, 2, &[&l0, &l2, &l2], None);
    built(&decode(&file, ColorSpace::Srgb).unwrap());
    // Level 0 of the wrong size is still an error.
    let file = plain_ktx2_levels(Format::R8G8B8A8_SRGB, 4, 2, &[&l1, &l1, &l2], None);
    let e = decode(&file, ColorSpace::Srgb).unwrap_err();
    assert!(e.contains("level 0 holds 8 stored bytes"), "{e}");
}

#[test]
fn the_budget_pays_for_every_level_before_decoding() {
    let (l0, l1, l2) = (flat(4, 2, RED), flat(2, 1, GREEN), flat(1, 1, BLUE));
    let one = plain_ktx2_levels(Format::R8G8B8A8_SRGB, 4, 2, &[&l0], None);
    let chain = plain_ktx2_levels(Format::R8G8B8A8_SRGB, 4, 2, &[&l0, &l1, &l2], None);
    // What a one-level file of 8 texels is charged: the texture, the decoded level 0 and the
    // transcoder's scratch. The chain's levels cost more, charged before anything is decoded.
    let level0_charge = 8 * (TEXTURE_BYTES_PER_TEXEL + 4 + TRANSCODER_SCRATCH_PER_TEXEL);
    let mut budget = Budget::new(level0_charge);
    decode_ktx2(&one, ColorSpace::Srgb, &mut budget).expect("level 0 fits");
    let mut budget = Budget::new(level0_charge);
    match decode_ktx2(&chain, ColorSpace::Srgb, &mut budget) {
        Err(ImageError::Budget(e)) => assert!(e.contains("4x2 KTX2 texture"), "{e}"),
        other => panic!("the chain fitted the budget of level 0: {other:?}"),
    }
}

#[test]
fn bottom_up_files_are_turned_top_down() {
    let rgba = quadrant_texels();
    let file = plain_ktx2(Format::R8G8B8A8_UNORM, 32, 32, &rgba, Some("ru"));
    let texture = decode(&file, ColorSpace::Linear).unwrap();
    // The file's first row is the bottom row of the picture.
    assert_eq!(texel(&texture, 8, 24), [200, 40, 40, 255]);
    assert_eq!(texel(&texture, 24, 8), [230, 220, 90, 128]);
    let file = plain_ktx2(Format::R8G8B8A8_UNORM, 32, 32, &rgba, Some("rd"));
    assert_eq!(
        texel(&decode(&file, ColorSpace::Linear).unwrap(), 8, 24),
        [30, 60, 200, 128]
    );
}

#[test]
fn other_formats_are_refused_by_name() {
    let file = plain_ktx2(Format::R16G16B16A16_SFLOAT, 2, 2, &[0; 32], None);
    let e = decode(&file, ColorSpace::Linear).unwrap_err();
    assert!(e.contains("R16G16B16A16_SFLOAT"), "{e}");
    assert!(!e.contains('\n'));
}

#[test]
fn broken_files_give_one_line_errors() {
    for (name, bytes) in [
        ("etc1s", ETC1S),
        ("etc1s-alpha", ETC1S_ALPHA),
        ("uastc-zstd", UASTC_ZSTD),
    ] {
        // Truncated at every length up to the whole file but one byte.
        for len in 0..bytes.len() {
            match decode(&bytes[..len], ColorSpace::Srgb) {
                Err(e) => assert!(!e.contains('\n') && !e.is_empty(), "{name}[..{len}]: {e}"),
                Ok(_) => panic!("{name} truncated to {len} bytes decoded"),
            }
        }
        // Every byte after the header flipped, one at a time: an error or a texture of the
        // header's size, never a panic (the bodies are compressed data the decoder must check).
        for at in 80..bytes.len() {
            let mut corrupt = bytes.to_vec();
            corrupt[at] ^= 0x5a;
            match decode(&corrupt, ColorSpace::Srgb) {
                Ok(t) => assert_eq!((t.width(), t.height()), (32, 32), "{name} byte {at}"),
                Err(e) => assert!(!e.contains('\n'), "{name} byte {at}: {e}"),
            }
        }
    }
}

/// Writes `value` at byte `at` of a copy of `bytes`.
fn patched(bytes: &[u8], at: usize, value: &[u8]) -> Vec<u8> {
    let mut out = bytes.to_vec();
    out[at..at + value.len()].copy_from_slice(value);
    out
}

#[test]
fn hostile_sizes_are_refused_before_decoding() {
    // Width and height beyond the texture limit.
    let huge = patched(
        &patched(ETC1S, 20, &100_000u32.to_le_bytes()),
        24,
        &100_000u32.to_le_bytes(),
    );
    let e = decode(&huge, ColorSpace::Srgb).unwrap_err();
    assert!(e.contains("100000x100000") && e.contains("outside"), "{e}");
    // A Zstandard level that claims 1 TiB once inflated: refused, nothing allocated.
    let claim = patched(UASTC_ZSTD, 80 + 16, &(1u64 << 40).to_le_bytes());
    let e = decode(&claim, ColorSpace::Srgb).unwrap_err();
    assert!(e.contains("1099511627776 decompressed bytes"), "{e}");
    // The largest size the limit allows, against a small budget: a budget error, before any
    // transcoding.
    let big = patched(
        &patched(UASTC_ZSTD, 20, &16384u32.to_le_bytes()),
        24,
        &16384u32.to_le_bytes(),
    );
    let big = patched(&big, 80 + 16, &(4096u64 * 4096 * 16).to_le_bytes());
    let mut budget = Budget::new(64 << 20);
    match decode_ktx2(&big, ColorSpace::Srgb, &mut budget) {
        Err(ImageError::Budget(e)) => assert!(e.contains("16384x16384 KTX2 texture"), "{e}"),
        Err(ImageError::Decode(e)) => panic!("a decode error, not a budget error: {e}"),
        Ok(_) => panic!("decoded a 16384x16384 claim"),
    }
    // A cube map.
    let cube = patched(ETC1S, 36, &6u32.to_le_bytes());
    assert!(decode(&cube, ColorSpace::Srgb)
        .unwrap_err()
        .contains("cube map"));
}

#[test]
fn ktx2_is_recognised_by_its_identifier_or_declared_type() {
    assert!(is_ktx2(ETC1S, None));
    assert!(is_ktx2(b"garbage", Some("image/ktx2")));
    assert!(!is_ktx2(b"garbage", Some("image/png")));
    // Data in another known format wins over a wrong declaration.
    assert!(!is_ktx2(b"\x89PNG\r\n\x1a\n rest", Some("image/ktx2")));
}

#[test]
fn fuzz_body_accepts_the_seeds_and_their_mutations() {
    let plain = plain_ktx2(
        Format::R8G8B8A8_SRGB,
        32,
        32,
        &quadrant_texels(),
        Some("rd"),
    );
    for seed in [ETC1S, ETC1S_ALPHA, UASTC_ZSTD, &plain] {
        fuzz(seed);
        for at in (0..seed.len()).step_by(7) {
            fuzz(&patched(seed, at, &[0xff]));
            fuzz(&seed[..at]);
        }
    }
}
