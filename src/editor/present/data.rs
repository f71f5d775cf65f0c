//! `render --data`: the frame as the data pictures see it (the document layer's
//! [`annotate`](crate::document::annotate)): each shown character's skinned vertices,
//! body parts and keypoints in the world, the floor, and the camera, taken from the ECS at
//! the moment the picture is captured.

use bevy::ecs::system::SystemParam;
use bevy::prelude::*;

use crate::document::annotate::{self, Figure, Pinhole, Surface, raster::FLOOR};
use crate::editor::present::stage::{Floor, floor_corners};
use crate::editor::scene_doc::document::{HumanoidMapOf, SceneCharacter};
use crate::editor::state::camera::OrbitCamera;
use crate::formats::scene::DisplayDoc;
use crate::scene::smpl::SmplCharacter;
use crate::scene::{Character, CharacterSkinning, CharacterView, JointScratch, SkinScratch, Slot};

/// What a data picture is made from.
pub struct DataFrame {
    pub camera: Pinhole,
    pub figures: Vec<Figure>,
    /// The floor's corners, where it is shown.
    pub floor: Option<[Vec3; 4]>,
}

impl DataFrame {
    /// The passes: the figures' triangles and the floor's, rasterised.
    pub fn passes(&self) -> annotate::Passes {
        let floor = self.floor.unwrap_or([Vec3::ZERO; 4]);
        let floor_triangles: &[[u32; 3]] = if self.floor.is_some() { &[[0, 2, 1], [0, 3, 2]] } else { &[] };
        let surfaces: Vec<Surface> = self
            .figures
            .iter()
            .map(Figure::surface)
            .chain([Surface { instance: FLOOR, positions: &floor, triangles: floor_triangles, parts: &[] }])
            .collect();
        annotate::rasterize(&self.camera, &surfaces)
    }

    /// Writes beside `picture` what `beside` asks, from one rasterisation of the frame: the
    /// ControlNet maps, and the data passes (then its COCO image, `ids.0`, and annotations,
    /// ids from `ids.1`, are returned).
    pub fn write_beside(
        &self,
        picture: &std::path::Path,
        ids: (u64, u64),
        beside: Beside,
    ) -> Result<Option<(serde_json::Value, Vec<serde_json::Value>)>, String> {
        let passes = self.passes();
        if let Some(maps) = beside.controlnet {
            annotate::write::controlnet(picture, &self.camera, &passes, &self.figures, maps)
                .map_err(|e| e.to_string())?;
        }
        if !beside.data {
            return Ok(None);
        }
        annotate::write::passes(picture, &self.camera, &passes, &self.figures).map_err(|e| e.to_string())?;
        let file_name = picture.file_name().map_or_else(String::new, |n| n.to_string_lossy().into_owned());
        let image = annotate::coco::image_json(ids.0, &file_name, &self.camera);
        Ok(Some((image, annotate::coco::annotations(&self.camera, &passes, &self.figures, ids.0, ids.1))))
    }

    /// What [`Self::write_beside`] writes, kept in memory, with the COCO file of this one
    /// picture (`file_name` its name there, `ids` its image's and first annotation's ids);
    /// `shown` is the picture (for its edges).
    pub fn keep_beside(
        self,
        file_name: &str,
        ids: (u64, u64),
        shown: &image::DynamicImage,
        beside: Beside,
    ) -> KeptBeside {
        let passes = self.passes();
        let (camera, figures) = (&self.camera, &self.figures);
        let controlnet = beside.controlnet.map(|maps| {
            let shown = if maps.canny.is_some() { shown.to_rgb8() } else { image::RgbImage::new(0, 0) };
            annotate::controlnet::maps(camera, &passes, figures, maps, &shown)
        });
        let coco = beside.data.then(|| {
            let image = annotate::coco::image_json(ids.0, file_name, camera);
            annotate::coco::file(vec![image], annotate::coco::annotations(camera, &passes, figures, ids.0, ids.1))
        });
        KeptBeside { camera: self.camera, passes, coco, controlnet }
    }

    /// [`Self::write_beside`], with the data's COCO file of this one picture.
    pub fn write_all_beside(&self, picture: &std::path::Path, beside: Beside) -> Result<(), String> {
        let Some((image, annotations)) = self.write_beside(picture, (1, 1), beside)? else { return Ok(()) };
        annotate::write::json(
            &annotate::write::beside(picture, "json"),
            &annotate::coco::file(vec![image], annotations),
        )
        .map_err(|e| e.to_string())
    }
}

/// What a picture carries beside it kept in memory ([`DataFrame::keep_beside`]) instead
/// of written: the camera and passes, the COCO file of the picture alone (with data), the
/// maps ControlNet reads.
pub struct KeptBeside {
    pub camera: Pinhole,
    pub passes: annotate::Passes,
    pub coco: Option<serde_json::Value>,
    pub controlnet: Option<annotate::controlnet::Maps>,
}

/// What a picture carries beside it: its data (depth, normals, masks, keypoints, COCO), the
/// maps ControlNet reads.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Beside {
    pub data: bool,
    pub controlnet: Option<annotate::controlnet::ControlNet>,
}

impl Beside {
    /// What a data set's spec asks beside each picture.
    pub fn of_spec(spec: &crate::document::generate::Spec) -> Self {
        let controlnet = spec.controlnet.then_some(annotate::controlnet::ControlNet { canny: spec.canny });
        Self { data: spec.data, controlnet }
    }
}

/// The ControlNet maps a panel asks for: whether, and whether with the canny edges at
/// thresholds kept while they are off.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ControlNetChoice {
    pub on: bool,
    pub canny: bool,
    pub thresholds: annotate::canny::Canny,
}

impl ControlNetChoice {
    /// The maps to write, if any.
    pub fn maps(&self) -> Option<annotate::controlnet::ControlNet> {
        self.on.then_some(annotate::controlnet::ControlNet { canny: self.canny.then_some(self.thresholds) })
    }
}

/// The ECS's view of what a data picture shows.
#[derive(SystemParam)]
pub struct DataScene<'w, 's> {
    characters: Query<
        'w,
        's,
        (
            &'static SceneCharacter,
            &'static Character,
            &'static SkinScratch,
            &'static JointScratch,
            &'static GlobalTransform,
            &'static CharacterView,
            &'static CharacterSkinning,
            Option<&'static HumanoidMapOf>,
            Has<SmplCharacter>,
            &'static Slot,
        ),
    >,
    floors: Query<'w, 's, (&'static Transform, &'static Visibility, &'static Slot), With<Floor>>,
    cameras: Query<'w, 's, (&'static OrbitCamera, &'static Slot)>,
}

impl DataScene<'_, '_> {
    /// The slot's frame now, for a picture of `width` × `height`. Characters are numbered in
    /// the order of their scene ids (from 1), so a sequence keeps each one's number.
    pub fn frame(&self, slot: Slot, width: u32, height: u32) -> Result<DataFrame, String> {
        Ok(self.frame_through(slot, self.camera(slot, width, height)?))
    }

    /// The slot's camera over a picture of `width` × `height`.
    pub fn camera(&self, slot: Slot, width: u32, height: u32) -> Result<Pinhole, String> {
        let (orbit, _) = self.cameras.iter().find(|c| *c.1 == slot).ok_or("the render has no camera")?;
        Pinhole::of(orbit, width, height).map_err(|e| e.to_string())
    }

    /// The slot's frame now, seen through `camera`.
    pub fn frame_through(&self, slot: Slot, camera: Pinhole) -> DataFrame {
        let mut characters: Vec<_> = self.characters.iter().filter(|c| *c.9 == slot).collect();
        characters.sort_by_key(|c| c.0.id);
        let figures = characters
            .into_iter()
            .enumerate()
            .filter(|(_, c)| c.5.0.visible && c.5.0.display != DisplayDoc::Skeleton)
            .map(|(k, (scene, character, skin, joints, place, _, method, map, smpl, _))| {
                let drawn = Drawn { character, skin, joints, method: method.0 };
                figure(k as u16 + 1, &scene.name, drawn, place.to_matrix(), map.map(|m| &m.0), smpl)
            })
            .collect();
        let floor = self
            .floors
            .iter()
            .find(|(_, v, s)| **v != Visibility::Hidden && **s == slot)
            .map(|(t, ..)| floor_corners(t));
        DataFrame { camera, figures, floor }
    }
}

/// A character as the picture draws it: its asset, its skin (empty when the GPU skins it),
/// its joints and its skinning method.
struct Drawn<'a> {
    character: &'a Character,
    skin: &'a SkinScratch,
    joints: &'a JointScratch,
    method: crate::rig::dqs::SkinningMethod,
}

/// One character as a figure: its skinned vertices (as drawn, by its own method) and
/// joints in the world, its vertices' body parts and its keypoints.
fn figure(
    instance: u16,
    name: &str,
    Drawn { character, skin, joints, method }: Drawn,
    world: Mat4,
    map: Option<&crate::rig::humanoid::HumanoidMap>,
    smpl: bool,
) -> Figure {
    let asset = &character.asset;
    let model = if skin.positions.len() == asset.vertex_count() {
        skin.positions.to_vec()
    } else {
        // Skinned on the GPU: the same method here.
        let palette: Vec<Mat4> =
            joints.matrices.iter().zip(&asset.bind_world_to_joint).map(|(m, bind)| *m * *bind).collect();
        let mut out = vec![Vec3::ZERO; asset.vertex_count()];
        crate::rig::dqs::skin_by(method, &asset.skin.bind_positions, &asset.skin.weights, &palette, &mut out);
        out
    };
    let positions: Vec<Vec3> = model.iter().map(|&p| world.transform_point3(p)).collect();
    let joint_world: Vec<Vec3> = joints.matrices.iter().map(|m| world.transform_point3(m.w_axis.truncate())).collect();
    Figure::new(name, instance, asset, map, positions, &joint_world, smpl)
}
