//! The value of an MTL texture statement (`map_Kd -s 2 2 1 -clamp on wood grain.png`): its
//! options and its file name.
//!
//! Every option of the MTL specification and of the common extensions is read with its
//! arguments: `-s`, `-o`, `-t` (one to three numbers), `-mm` (one or two), `-bm`, `-boost`,
//! `-texres` (one), `-clamp`, `-blendu`, `-blendv`, `-cc` (`on` / `off`), `-imfchan`
//! (`r g b m l z`), `-type` and `-colorspace` (one word). The file name is what remains; it
//! may hold spaces and may come before options (`bump.png -bm 0.5`), and surrounding double
//! quotes are removed. Which options a material applies is the loader's business
//! (`obj_material`); this module only reads them.

use glam::Vec2;
use kantele_rules::shade::texture::ColorSpace;

/// A channel of an image read as a scalar (`-imfchan`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Channel {
    /// `r`.
    Red,
    /// `g`.
    Green,
    /// `b`.
    Blue,
    /// `m` (matte): the alpha channel.
    Alpha,
    /// `l`, and `z` (depth, which images do not have): `0.2126 r + 0.7152 g + 0.0722 b`.
    Luminance,
}

/// What a texture statement's options ask for.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TextureOptions {
    /// `-s u v`: texture coordinates are multiplied by it (default 1 1).
    pub scale: Vec2,
    /// `-o u v`: then offset by it (default 0 0).
    pub offset: Vec2,
    /// `-clamp on`: the texture is not repeated.
    pub clamp: bool,
    /// `-bm`: the bump (normal) map's strength.
    pub bump_multiplier: Option<f32>,
    /// `-colorspace sRGB | linear`: how the texels are encoded.
    pub color_space: Option<ColorSpace>,
    /// `-imfchan`: the channel a scalar texture reads.
    pub channel: Option<Channel>,
    /// The options given, in order (as written, lower case), for the loader to tell which it
    /// applies.
    pub given: Vec<String>,
}

impl Default for TextureOptions {
    fn default() -> Self {
        Self {
            scale: Vec2::ONE,
            offset: Vec2::ZERO,
            clamp: false,
            bump_multiplier: None,
            color_space: None,
            channel: None,
            given: Vec::new(),
        }
    }
}

impl TextureOptions {
    /// Whether `-s` or `-o` moves the texture coordinates.
    pub(crate) fn moves_coordinates(&self) -> bool {
        self.scale != Vec2::ONE || self.offset != Vec2::ZERO
    }
}

/// A texture statement's file name and options.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TextureRef {
    /// The file name, relative to the MTL file's folder (`\` not yet turned into `/`).
    pub file: String,
    /// Its options.
    pub options: TextureOptions,
}

/// The arguments an option takes.
enum Arguments {
    /// Between `min` and `max` numbers.
    Numbers(usize, usize),
    /// `on` or `off`.
    Switch,
    /// One of `r g b m l z`.
    Channel,
    /// Any one word.
    Word,
}

/// The arguments of a known option, by its lower-case name.
fn arguments(option: &str) -> Option<Arguments> {
    Some(match option {
        "-s" | "-o" | "-t" => Arguments::Numbers(1, 3),
        "-mm" => Arguments::Numbers(1, 2),
        "-bm" | "-boost" | "-texres" => Arguments::Numbers(1, 1),
        "-clamp" | "-blendu" | "-blendv" | "-cc" => Arguments::Switch,
        "-imfchan" => Arguments::Channel,
        "-type" | "-colorspace" => Arguments::Word,
        _ => return None,
    })
}

fn number(word: &str) -> Option<f32> {
    word.parse::<f32>().ok().filter(|v| v.is_finite())
}

fn channel(word: &str) -> Option<Channel> {
    Some(match word.to_ascii_lowercase().as_str() {
        "r" => Channel::Red,
        "g" => Channel::Green,
        "b" => Channel::Blue,
        "m" => Channel::Alpha,
        "l" | "z" => Channel::Luminance,
        _ => return None,
    })
}

/// Reads a texture statement's value; the warnings say what could not be read (an option
/// without its arguments, an unknown option, words after the file name). `None` when there is
/// no file name.
pub(crate) fn parse_texture(value: &str) -> (Option<TextureRef>, Vec<String>) {
    // The words with their byte ranges, so that the name keeps its own spacing.
    let words: Vec<(usize, &str)> = value
        .split_whitespace()
        .map(|w| (w.as_ptr() as usize - value.as_ptr() as usize, w))
        .collect();
    let mut options = TextureOptions::default();
    let mut warnings = Vec::new();
    let mut name: Option<(usize, usize)> = None;
    let mut name_ended = false;
    let mut i = 0;
    while i < words.len() {
        let (at, word) = words[i];
        let option = word.to_ascii_lowercase();
        let known = arguments(&option);
        let is_last = i + 1 == words.len();
        // A word that starts with '-' is an option, unless it is not a known one and the
        // name has begun (`my -old- wood.png`) or nothing follows it (`-x.png`).
        let is_option = word.starts_with('-') && (known.is_some() || (name.is_none() && !is_last));
        if !is_option {
            if name_ended {
                warnings.push(format!("'{word}' after the file name is ignored"));
            } else {
                let start = name.map_or(at, |(start, _)| start);
                name = Some((start, at + word.len()));
            }
            i += 1;
            continue;
        }
        name_ended |= name.is_some();
        i += 1;
        let next = |i: usize| words.get(i).map(|&(_, w)| w);
        match known {
            None => {
                // Skip its arguments: the numbers and switches that follow.
                while next(i).is_some_and(|w| number(w).is_some() || matches!(w, "on" | "off")) {
                    i += 1;
                }
                warnings.push(format!("unknown texture option '{word}' is skipped"));
                continue;
            }
            Some(Arguments::Numbers(min, max)) => {
                let mut values = Vec::new();
                while values.len() < max {
                    match next(i).and_then(number) {
                        Some(v) => values.push(v),
                        None => break,
                    }
                    i += 1;
                }
                if values.len() < min {
                    warnings.push(format!("texture option '{word}' needs a number; skipped"));
                    continue;
                }
                let pair =
                    |default: f32| Vec2::new(values[0], values.get(1).copied().unwrap_or(default));
                match option.as_str() {
                    "-s" => options.scale = pair(1.0),
                    "-o" => options.offset = pair(0.0),
                    "-bm" => options.bump_multiplier = Some(values[0]),
                    _ => {}
                }
            }
            Some(Arguments::Switch) => match next(i).map(str::to_ascii_lowercase).as_deref() {
                Some(switch @ ("on" | "off")) => {
                    i += 1;
                    if option == "-clamp" {
                        options.clamp = switch == "on";
                    }
                }
                _ => {
                    warnings.push(format!("texture option '{word}' needs on or off; skipped"));
                    continue;
                }
            },
            Some(Arguments::Channel) => match next(i).and_then(channel) {
                Some(c) => {
                    i += 1;
                    options.channel = Some(c);
                }
                None => {
                    warnings.push(format!(
                        "texture option '{word}' needs one of r, g, b, m, l, z; skipped"
                    ));
                    continue;
                }
            },
            Some(Arguments::Word) => match next(i) {
                Some(argument) => {
                    i += 1;
                    if option == "-colorspace" {
                        match argument.to_ascii_lowercase().as_str() {
                            "srgb" => options.color_space = Some(ColorSpace::Srgb),
                            "linear" | "raw" => options.color_space = Some(ColorSpace::Linear),
                            _ => warnings.push(format!(
                                "colour space '{argument}' is not sRGB or linear; skipped"
                            )),
                        }
                    }
                }
                None => {
                    warnings.push(format!("texture option '{word}' needs a value; skipped"));
                    continue;
                }
            },
        }
        if !options.given.contains(&option) {
            options.given.push(option);
        }
    }
    let file = name.map(|(start, end)| {
        let file = &value[start..end];
        file.strip_prefix('"')
            .and_then(|f| f.strip_suffix('"'))
            .unwrap_or(file)
            .to_string()
    });
    match file {
        Some(file) if !file.is_empty() => (Some(TextureRef { file, options }), warnings),
        _ => {
            warnings.push("no texture file name".to_string());
            (None, warnings)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(value: &str) -> String {
        parse_texture(value).0.expect("a file").file
    }

    #[test]
    fn the_name_is_what_the_options_leave() {
        assert_eq!(file("wood.png"), "wood.png");
        assert_eq!(file("  my  wood.png "), "my  wood.png");
        assert_eq!(file("-s 1 1 1 wood.png"), "wood.png");
        assert_eq!(file("-clamp on -bm 0.5 my wood.png"), "my wood.png");
        assert_eq!(file("-colorspace sRGB -o 0.1 diffuse.jpg"), "diffuse.jpg");
        assert_eq!(file("-type cube_top specular.jpg"), "specular.jpg");
        assert_eq!(file("-imfchan r bumpmap2.jpg -bm 1.5"), "bumpmap2.jpg");
        assert_eq!(
            file("-t 0.1 0.2 0.3 -mm 0.1 0.3 -texres 512 a.png"),
            "a.png"
        );
        assert_eq!(
            file("-blendu on -blendv off -cc off -boost 2 a.png"),
            "a.png"
        );
        assert_eq!(file("my -old- wood.png"), "my -old- wood.png");
        assert_eq!(file("-odd.png"), "-odd.png");
        assert_eq!(file("\"with space.png\""), "with space.png");
        assert_eq!(file("C:\\textures\\wood 1.png"), "C:\\textures\\wood 1.png");
    }

    #[test]
    fn options_are_read() {
        let (t, warnings) = parse_texture(
            "-s 2 3 1 -o 0.5 -CLAMP on -bm 0.25 -imfchan g -colorspace linear -blendu off x.png",
        );
        assert!(warnings.is_empty(), "{warnings:?}");
        let o = t.expect("a file").options;
        assert_eq!(o.scale, Vec2::new(2.0, 3.0));
        assert_eq!(o.offset, Vec2::new(0.5, 0.0));
        assert!(o.clamp && o.moves_coordinates());
        assert_eq!(o.bump_multiplier, Some(0.25));
        assert_eq!(o.channel, Some(Channel::Green));
        assert_eq!(o.color_space, Some(ColorSpace::Linear));
        assert_eq!(
            o.given,
            [
                "-s",
                "-o",
                "-clamp",
                "-bm",
                "-imfchan",
                "-colorspace",
                "-blendu"
            ]
        );
        assert_eq!(
            parse_texture("-colorspace sRGB a.png")
                .0
                .unwrap()
                .options
                .color_space,
            Some(ColorSpace::Srgb)
        );
    }

    #[test]
    fn what_cannot_be_read_is_a_warning() {
        let (t, warnings) = parse_texture("-halo 2 -s a.png -clamp maybe");
        assert_eq!(t.expect("a file").file, "a.png");
        assert_eq!(warnings.len(), 4, "{warnings:?}");
        assert!(warnings[0].contains("-halo"));
        assert!(warnings[1].contains("-s"));
        assert!(warnings[2].contains("-clamp"));
        assert!(warnings[3].contains("'maybe'"));
        let (t, warnings) = parse_texture("a b.png -bm 1 c.png");
        assert_eq!(t.expect("a file").file, "a b.png");
        assert_eq!(warnings, ["'c.png' after the file name is ignored"]);
        let (t, warnings) = parse_texture("-bm 2");
        assert!(t.is_none());
        assert_eq!(warnings, ["no texture file name"]);
        assert!(parse_texture("").0.is_none());
    }
}
