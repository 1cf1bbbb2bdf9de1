//! The image files of an OBJ file's materials as scene textures: each file read under the read
//! policy and the budget and decoded once per colour space (sRGB for colours, linear for data),
//! and each texture, whether decoded from a file or made from two (`mtl_texels`), added to the
//! scene once. A file that cannot be read or decoded is a warning naming it (an error under
//! `strict`), given once per file and for at most [`MAX_TEXTURE_WARNINGS`] files; a texture
//! that would exceed the budget always stops the load.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use kantele_rules::scene::Scene;
use kantele_rules::shade::texture::{ColorSpace, Texture};

use crate::budget::Budget;
use crate::mtl_texture::Channel;
use crate::read_policy::ReadPolicy;
use crate::texture_util::{decode_within, image_size, placeholder, ImageError};
use crate::{LoadOptions, SceneInfo};

/// Files that get a warning of their own; the others are counted in one line.
pub(crate) const MAX_TEXTURE_WARNINGS: usize = 32;

/// A decoded image (a placeholder when textures are not decoded) and its size as its header
/// declares it.
#[derive(Clone, Debug)]
pub(crate) struct Image {
    /// The texture.
    pub texture: Arc<Texture>,
    /// Width and height.
    pub size: (u32, u32),
}

/// An image file read in a colour space.
pub(crate) type FileKey = (PathBuf, ColorSpace);

/// What a scene texture was made from.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub(crate) enum Made {
    /// An image file as it is.
    File(FileKey),
    /// A base colour (or white) with the alpha of a channel of another image.
    BaseWithAlpha {
        /// The colour's image.
        color: Option<FileKey>,
        /// The alpha's image and channel.
        alpha: (FileKey, Channel),
    },
    /// A metallic-roughness texture from one channel of each of two images.
    MetallicRoughness {
        /// The roughness image and channel.
        roughness: Option<(FileKey, Channel)>,
        /// The metallic image and channel.
        metallic: Option<(FileKey, Channel)>,
    },
}

/// The textures of one OBJ load.
#[derive(Debug)]
pub(crate) struct ObjTextures<'a> {
    policy: &'a ReadPolicy,
    options: &'a LoadOptions,
    /// Images by file and colour space (`None`: could not be read or decoded).
    images: HashMap<FileKey, Option<Image>>,
    /// Files that could not be read (not tried again in another colour space).
    failed: HashSet<PathBuf>,
    /// Scene textures by what they were made from.
    made: HashMap<Made, usize>,
    /// Files that could not be read beyond [`MAX_TEXTURE_WARNINGS`].
    unreported: usize,
}

impl<'a> ObjTextures<'a> {
    /// No textures yet.
    pub(crate) fn new(policy: &'a ReadPolicy, options: &'a LoadOptions) -> Self {
        Self {
            policy,
            options,
            images: HashMap::new(),
            failed: HashSet::new(),
            made: HashMap::new(),
            unreported: 0,
        }
    }

    /// Whether textures are decoded (otherwise images are placeholders of their size).
    pub(crate) fn decoded(&self) -> bool {
        self.options.decode_textures
    }

    /// The image of `file` decoded in `color_space`; `None` (with a warning that starts with
    /// `what`) when it cannot be read or decoded. An error when that is `strict`, or when the
    /// texture exceeds the budget.
    pub(crate) fn image(
        &mut self,
        file: &Path,
        color_space: ColorSpace,
        what: &str,
        budget: &mut Budget,
        info: &mut SceneInfo,
    ) -> Result<Option<Image>, String> {
        let key = (file.to_path_buf(), color_space);
        if let Some(image) = self.images.get(&key) {
            return Ok(image.clone());
        }
        if self.failed.contains(file) {
            return Ok(None);
        }
        let image = match self.load(file, color_space, budget) {
            Ok((texture, size)) => Some(Image {
                texture: Arc::new(texture),
                size,
            }),
            Err(ImageError::Budget(e)) => return Err(format!("{what}: {e}")),
            Err(ImageError::Decode(e)) if self.options.strict => {
                return Err(format!("{what}: {e}"))
            }
            Err(ImageError::Decode(e)) => {
                self.failed.insert(file.to_path_buf());
                if self.failed.len() <= MAX_TEXTURE_WARNINGS {
                    info.warn(format!(
                        "{what}: {e}; drawn untextured (--strict makes this an error)"
                    ));
                } else {
                    self.unreported += 1;
                }
                None
            }
        };
        self.images.insert(key, image.clone());
        Ok(image)
    }

    /// Reads and decodes an image file (a placeholder when textures are not decoded); with
    /// its header size.
    fn load(
        &self,
        file: &Path,
        color_space: ColorSpace,
        budget: &mut Budget,
    ) -> Result<(Texture, (u32, u32)), ImageError> {
        let bytes = self.policy.read(file, budget).map_err(|e| {
            if e.contains("memory budget") {
                ImageError::Budget(e)
            } else {
                ImageError::Decode(e)
            }
        })?;
        let size = image_size(&bytes, None)?;
        if !self.options.decode_textures {
            return Ok((placeholder(), size));
        }
        Ok((decode_within(&bytes, None, color_space, budget)?, size))
    }

    /// The scene texture made from `made`: added to the scene (with its size) by `make` the
    /// first time.
    pub(crate) fn scene_texture(
        &mut self,
        made: Made,
        scene: &mut Scene,
        info: &mut SceneInfo,
        make: impl FnOnce() -> Result<Image, String>,
    ) -> Result<usize, String> {
        if let Some(&index) = self.made.get(&made) {
            return Ok(index);
        }
        let image = make()?;
        scene.textures.push(image.texture);
        info.texture_sizes.push(image.size);
        let index = scene.textures.len() - 1;
        self.made.insert(made, index);
        Ok(index)
    }

    /// Adds the line that counts the files not warned about one by one.
    pub(crate) fn finish(&self, info: &mut SceneInfo) {
        if self.unreported > 0 {
            info.warn(format!(
                "{} more texture files could not be read; drawn untextured",
                self.unreported
            ));
        }
    }
}
