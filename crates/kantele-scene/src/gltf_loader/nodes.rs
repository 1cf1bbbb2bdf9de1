//! The node hierarchy: the walk from the scene's roots (draws, cameras, the light), instancing
//! (`EXT_mesh_gpu_instancing`) and the scene's extras.

use glam::{Mat4, Quat, Vec3, Vec4};
use kantele_rules::scene::{Draw, Light, LightKind, NamedCamera, PunctualLight, Shading};

use super::{capped_name, named, Loader, DEFAULT_RESOLUTION};
use crate::accessor::{read_f32, BufferData};
use crate::mesh_util::framing_camera;
use crate::{LoadError, LoadedScene};

/// The smallest near plane a perspective file camera keeps, as a fraction of the distance to
/// the far side of the scene ([`Loader::raise_near_planes`]): depths there still differ from
/// the far plane's by about 30 steps of 32-bit float.
const MIN_NEAR_FRACTION: f32 = 1e-6;

impl Loader<'_> {
    pub(super) fn run(mut self) -> Result<LoadedScene, LoadError> {
        let document = self.document;
        self.info.node_count = document.nodes().len();
        self.info.cameras = document
            .cameras()
            .map(|c| named(c.name(), "camera", c.index()))
            .collect();
        self.info.lights = document
            .lights()
            .map(|lights| {
                lights
                    .map(|l| named(l.name(), "light", l.index()))
                    .collect()
            })
            .unwrap_or_default();
        self.catalogue()?;
        for material in document.materials() {
            let converted = self.material(&material)?;
            self.scene.materials.push(converted);
        }
        self.prepare_rig()?;

        let Some(gltf_scene) = self.chosen_scene()? else {
            self.info.warn("the file has no scene: nothing is drawn");
            self.scene.camera = framing_camera(&self.scene);
            return Ok(LoadedScene {
                scene: self.scene,
                info: self.info,
                animation: None,
            });
        };
        self.extras(&gltf_scene);

        let mut camera = None;
        let mut light = None;
        let mut visited = vec![false; document.nodes().len()];
        // Depth first, each node before its children, in file order.
        let mut stack: Vec<(gltf::Node, Mat4, Option<usize>)> = gltf_scene
            .nodes()
            .map(|n| (n, Mat4::IDENTITY, None))
            .collect();
        stack.reverse();
        while let Some((node, parent, parent_index)) = stack.pop() {
            let index = node.index();
            if std::mem::replace(&mut visited[index], true) {
                self.info.warn(format!(
                    "node {index} is reached more than once (the node hierarchy is not a tree); drawn once"
                ));
                continue;
            }
            self.rig_visit(index, parent_index);
            let local = Mat4::from_cols_array_2d(&node.transform().matrix());
            let world = parent * local;
            if let Some(c) = self.camera(&node, world) {
                let name = node
                    .camera()
                    .map(|c| named(c.name(), "camera", c.index()))
                    .unwrap_or_default();
                self.scene
                    .file_cameras
                    .push(NamedCamera { name, camera: c });
                self.rig_camera(self.scene.file_cameras.len() - 1, index);
                if camera.is_none() {
                    camera = Some(c);
                }
            }
            if let Some(l) = node.light() {
                let color = Vec3::from(l.color()) * l.intensity();
                let kind = match l.kind() {
                    gltf::khr_lights_punctual::Kind::Directional => {
                        if light.is_none() {
                            light = Some(Light::Directional {
                                to_light: world.transform_vector3(Vec3::Z).normalize_or_zero(),
                                color,
                            });
                            self.rig_directional(index);
                        }
                        LightKind::Directional
                    }
                    gltf::khr_lights_punctual::Kind::Point => LightKind::Point,
                    gltf::khr_lights_punctual::Kind::Spot {
                        inner_cone_angle,
                        outer_cone_angle,
                    } => LightKind::Spot {
                        inner_cone_angle,
                        outer_cone_angle,
                    },
                };
                let punctual = PunctualLight {
                    kind,
                    color,
                    position: world.transform_point3(Vec3::ZERO),
                    direction: world.transform_vector3(Vec3::NEG_Z).normalize_or_zero(),
                    range: l.range(),
                };
                if punctual.color.is_finite() && punctual.position.is_finite() {
                    self.scene.lights.push(punctual);
                    self.rig_light(self.scene.lights.len() - 1, index);
                } else {
                    self.info.warn(format!(
                        "light '{}' has a non-finite colour or position; left out",
                        named(l.name(), "light", l.index())
                    ));
                }
            }
            if let Some(mesh) = node.mesh() {
                // Default morph weights: the node's, else the mesh's (the rest pose).
                let weights: Vec<f32> = node
                    .weights()
                    .or(mesh.weights())
                    .map(<[f32]>::to_vec)
                    .unwrap_or_default();
                let instances = self.instances(&node)?;
                for primitive in mesh.primitives() {
                    let key = (
                        mesh.index(),
                        primitive.index(),
                        weights.iter().map(|w| w.to_bits()).collect::<Vec<u32>>(),
                    );
                    let (mesh_index, skinned) = if self.deformed(&node, &primitive) {
                        let (m, skinned) = self.deformable_primitive(&node, &mesh, &primitive)?;
                        (Some(m), skinned)
                    } else {
                        match self.primitive_meshes.get(&key) {
                            Some(&m) => (m, false),
                            None => {
                                let m = self.primitive(&mesh, &primitive, &weights)?;
                                self.primitive_meshes.insert(key, m);
                                (m, false)
                            }
                        }
                    };
                    if let Some(mesh_index) = mesh_index {
                        let count = instances.as_ref().map_or(1, Vec::len);
                        self.budget
                            .charge(count as u64, 128, "the draws of a node")
                            .map_err(|e| self.invalid(e))?;
                        for i in 0..count {
                            let instance = instances.as_ref().map(|list| list[i]);
                            // Posing places skinned draws (see `pose`); until then, the node.
                            let model = instance.map_or(world, |m| world * m);
                            self.scene.draws.push(Draw {
                                mesh: mesh_index,
                                model,
                                node_name: capped_name(node.name().unwrap_or_default()),
                                node_index: index,
                            });
                            self.rig_draw(self.scene.draws.len() - 1, index, instance, skinned)?;
                        }
                    }
                }
            }
            let children: Vec<_> = node.children().collect();
            for child in children.into_iter().rev() {
                stack.push((child, world, Some(index)));
            }
        }

        self.scene.light = light.unwrap_or(Light::Headlight);
        let animation = self.finish_rig()?;
        self.raise_near_planes();
        // The first file camera, as posed.
        let camera = camera.and(self.scene.file_cameras.first().map(|c| c.camera));
        self.choose_shading()?;
        match camera {
            Some(camera) => {
                self.scene.camera = camera;
                self.info.camera_from_file = true;
            }
            None => {
                self.scene.camera = framing_camera(&self.scene);
                self.info.camera_from_file = false;
            }
        }
        self.scene
            .validate()
            .map_err(|e| self.invalid(e.to_string()))?;
        Ok(LoadedScene {
            scene: self.scene,
            info: self.info,
            animation,
        })
    }

    /// Raises, with a warning, the near plane of each perspective file camera that is so close
    /// that 32-bit depth cannot tell the scene from the far plane: depth `1 − 2 znear / d` rounds
    /// to 1 once `d / znear` passes about 2²⁴, and the scene then counts as outside the view
    /// volume (an empty picture, without the empty-picture warning). The near plane becomes at
    /// least [`MIN_NEAR_FRACTION`] of the distance from the camera to the far side of the scene.
    fn raise_near_planes(&mut self) {
        let Some((center, radius)) = self.scene.bounding_sphere() else {
            return;
        };
        for named in &mut self.scene.file_cameras {
            let camera = &mut named.camera;
            if camera.ymag.is_some() {
                continue;
            }
            let eye = camera.view.inverse().transform_point3(Vec3::ZERO);
            let reach = (eye - center).length() + radius;
            let least = reach * MIN_NEAR_FRACTION;
            if reach.is_finite() && camera.znear < least {
                self.info.warn(format!(
                    "camera '{}': its near plane ({:e}) is too close for the depth buffer over a scene {reach:.3e} away; raised to {least:.3e}",
                    named.name, camera.znear
                ));
                camera.znear = least;
            }
        }
    }

    /// The instance transforms of `EXT_mesh_gpu_instancing` a node's mesh is drawn with (each
    /// drawn with world × the instance's TRS); `None` without instancing.
    fn instances(&mut self, node: &gltf::Node) -> Result<Option<Vec<Mat4>>, LoadError> {
        let Some(ext) = node.extension_value("EXT_mesh_gpu_instancing") else {
            return Ok(None);
        };
        let what = format!("node {} (EXT_mesh_gpu_instancing)", node.index());
        let attributes = ext.get("attributes").and_then(|a| a.as_object());
        let data = BufferData {
            buffers: self.buffers,
            decoded_views: self.decoded_views,
        };
        let mut read = |name: &str, components: usize| -> Result<Option<Vec<f32>>, LoadError> {
            let Some(index) = attributes
                .and_then(|a| a.get(name))
                .and_then(|v| v.as_u64())
            else {
                return Ok(None);
            };
            let accessor = self
                .document
                .accessors()
                .nth(index as usize)
                .ok_or_else(|| {
                    LoadError::invalid(self.path, format!("{what}: no accessor {index}"))
                })?;
            if accessor.dimensions().multiplicity() != components {
                return Err(LoadError::invalid(
                    self.path,
                    format!("{what}: {name} accessor {index} has the wrong type"),
                ));
            }
            let label = format!("{what}: {name} accessor {index}");
            read_f32(&data, &accessor, &mut self.budget, &label)
                .map(Some)
                .map_err(|e| LoadError::invalid(self.path, e))
        };
        let translation = read("TRANSLATION", 3)?;
        let rotation = read("ROTATION", 4)?;
        let scale = read("SCALE", 3)?;
        let counts = [
            translation.as_ref().map(|t| t.len() / 3),
            rotation.as_ref().map(|r| r.len() / 4),
            scale.as_ref().map(|s| s.len() / 3),
        ];
        let mut known = counts.iter().flatten();
        let Some(&count) = known.next() else {
            return Ok(None);
        };
        if known.any(|&c| c != count) {
            return Err(self.invalid(format!(
                "{what}: the instance attributes have different counts"
            )));
        }
        let mut models =
            crate::budget::vec_with_capacity(count, &what).map_err(|e| self.invalid(e))?;
        for i in 0..count {
            let t = translation
                .as_ref()
                .map_or(Vec3::ZERO, |t| Vec3::from_slice(&t[3 * i..]));
            let r = rotation.as_ref().map_or(Quat::IDENTITY, |r| {
                let q = Vec4::from_slice(&r[4 * i..]);
                q.try_normalize().map_or(Quat::IDENTITY, Quat::from_vec4)
            });
            let s = scale
                .as_ref()
                .map_or(Vec3::ONE, |s| Vec3::from_slice(&s[3 * i..]));
            models.push(Mat4::from_scale_rotation_translation(s, r, t));
        }
        Ok(Some(models))
    }

    /// Decides the shading model (see [`crate::LoadOptions::shading`]) and sets up what goes
    /// with it ([`crate::shading::apply`]).
    fn choose_shading(&mut self) -> Result<(), LoadError> {
        let default = self.default_shading();
        crate::shading::apply(
            &mut self.scene,
            &mut self.info,
            self.options,
            default,
            self.clear_color_given,
            &mut self.budget,
        )
        .map_err(|e| self.invalid(e))
    }

    /// The shading the file gets without `--shading`: Lambert for a reference scene (its
    /// extras carry `ambient`, read by [`Self::extras`]), PBR for every other.
    fn default_shading(&self) -> Shading {
        if self.reference_extras {
            Shading::Lambert
        } else {
            Shading::Pbr
        }
    }

    /// The shading the scene is drawn with (known once the scene's extras are read).
    pub(super) fn shading(&self) -> Shading {
        self.options.shading.unwrap_or(self.default_shading())
    }

    /// Reads `resolution`, `clear_color` and `ambient` from the scene's extras.
    fn extras(&mut self, gltf_scene: &gltf::Scene) {
        self.scene.resolution = DEFAULT_RESOLUTION;
        self.scene.clear_color = Vec4::new(0.0, 0.0, 0.0, 1.0);
        self.scene.ambient = 0.1;
        let Some(raw) = gltf_scene.extras() else {
            return;
        };
        let value: serde_json::Value = match serde_json::from_str(raw.get()) {
            Ok(v) => v,
            Err(e) => {
                self.info
                    .warn(format!("scene extras are not valid JSON ({e}); ignored"));
                return;
            }
        };
        let numbers = |v: &serde_json::Value| -> Option<Vec<f64>> {
            v.as_array()?
                .iter()
                .map(serde_json::Value::as_f64)
                .collect()
        };
        if let Some(v) = value.get("resolution") {
            let max = kantele_rules::MAX_TARGET_SIZE as f64;
            match numbers(v).as_deref() {
                Some(&[w, h])
                    if w >= 1.0 && h >= 1.0 && w <= max && h <= max && w.fract() == 0.0 && h.fract() == 0.0 =>
                {
                    self.scene.resolution = (w as u32, h as u32);
                }
                _ => self.info.warn(format!(
                    "scene extras: resolution {v} is not [width, height] in 1..={max}; using 800x600"
                )),
            }
        }
        if let Some(v) = value.get("clear_color") {
            match numbers(v).as_deref() {
                Some(&[r, g, b, a]) if [r, g, b, a].iter().all(|c| c.is_finite()) => {
                    self.scene.clear_color = Vec4::new(r as f32, g as f32, b as f32, a as f32);
                    self.clear_color_given = true;
                }
                Some(&[r, g, b]) if [r, g, b].iter().all(|c| c.is_finite()) => {
                    self.scene.clear_color = Vec4::new(r as f32, g as f32, b as f32, 1.0);
                    self.clear_color_given = true;
                }
                _ => self.info.warn(format!(
                    "scene extras: clear_color {v} is not [r, g, b, a]; using black"
                )),
            }
        }
        if let Some(v) = value.get("ambient") {
            self.reference_extras = true;
            match v.as_f64() {
                Some(a) if a.is_finite() => self.scene.ambient = a as f32,
                _ => self.info.warn(format!(
                    "scene extras: ambient {v} is not a number; using 0.1"
                )),
            }
        }
    }
}
