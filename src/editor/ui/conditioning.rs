//! The ControlNet maps live in the viewport, as the web pose editors show them: with the
//! View toggle on, the OpenPose drawing (or the relative inverse depth, or the Normal 1.1
//! normals) of the frame now is drawn over the 3D view inside the frame guide, at the
//! guide's pixels, by the same code as `render --controlnet`. It is worked out again only
//! when what it shows changes (a pose, a placement, the camera, the guide's size, the map
//! asked for); idle, nothing is drawn.

use std::hash::{Hash, Hasher};

use bevy::prelude::*;
use bevy::window::{PrimaryWindow, RequestRedraw};
use bevy_egui::egui;

use crate::document::annotate::controlnet::{inverse_depth, normal_map, openpose_drawing, people};
use crate::editor::interact::pointer::ViewportArea;
use crate::editor::order::EditorSystems;
use crate::editor::present::data::DataScene;
use crate::editor::state::ShotSettings;
use crate::editor::state::camera::OrbitCamera;
use crate::scene::{CharacterView, JointScratch, SkinScratch, Slot};

/// Which ControlNet map the viewport shows over the 3D view.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ConditioningMap {
    OpenPose,
    Depth,
    Normal,
}

impl ConditioningMap {
    pub const ALL: [Self; 3] = [Self::OpenPose, Self::Depth, Self::Normal];

    pub fn label(self) -> &'static str {
        match self {
            Self::OpenPose => "OpenPose",
            Self::Depth => "depth",
            Self::Normal => "normal",
        }
    }
}

/// The View toggle and what it shows now.
#[derive(Resource, Default)]
pub struct ConditioningOverlay {
    /// The map shown over the view; none: the toggle is off.
    pub map: Option<ConditioningMap>,
    /// A digest of what the map was last worked out from.
    digest: Option<u64>,
    /// The map worked out, not yet handed to egui.
    pending: Option<Image>,
    /// The map's picture, and egui's name for it while the toggle is on.
    image: Handle<Image>,
    shown: Option<egui::TextureId>,
    /// How many times the map has been worked out (each a change of what it shows).
    pub drawn: u64,
}

impl ConditioningOverlay {
    /// The texture to draw inside the frame guide, while the toggle is on.
    pub fn texture(&self) -> Option<egui::TextureId> {
        self.map.and(self.shown)
    }
}

pub struct ConditioningOverlayPlugin;

impl Plugin for ConditioningOverlayPlugin {
    fn build(&self, app: &mut App) {
        crate::editor::order::add_editor_order(app);
        app.init_resource::<ConditioningOverlay>().add_systems(
            PostUpdate,
            (work_out_the_overlay_on_change, hand_the_overlay_to_egui).chain().in_set(EditorSystems::Present),
        );
    }
}

/// The frame guide's rectangle in `viewport`: the shot's aspect at the viewport's height or
/// width, centred.
pub fn frame_rect(viewport: egui::Rect, shot: &crate::formats::scene::ShotDoc) -> egui::Rect {
    let aspect = shot.width as f32 / shot.height.max(1) as f32;
    let size = if viewport.width() / viewport.height().max(1.0) > aspect {
        egui::vec2(viewport.height() * aspect, viewport.height())
    } else {
        egui::vec2(viewport.width(), viewport.width() / aspect)
    };
    egui::Rect::from_center_size(viewport.center(), size)
}

/// Works out the map again where what it shows changed, and asks for the frame that shows it.
#[allow(clippy::too_many_arguments)]
pub fn work_out_the_overlay_on_change(
    mut overlay: ResMut<ConditioningOverlay>,
    scene: DataScene,
    area: Res<ViewportArea>,
    shot: Res<ShotSettings>,
    windows: Query<&Window, With<PrimaryWindow>>,
    characters: Query<(&JointScratch, &SkinScratch, &GlobalTransform, &CharacterView)>,
    cameras: Query<&OrbitCamera>,
    mut redraw: MessageWriter<RequestRedraw>,
) {
    let Some(map) = overlay.map else {
        if overlay.digest.is_some() {
            (overlay.digest, overlay.shown) = (None, None);
        }
        return;
    };
    let (Some(area), Ok(window)) = (area.0, windows.single()) else { return };
    let scale = window.scale_factor();
    let viewport = egui::Rect::from_min_max(egui::pos2(area.min.x, area.min.y), egui::pos2(area.max.x, area.max.y));
    let frame = frame_rect(viewport, &shot.0);
    let pixels = |v: f32| (v * scale).round().max(1.0) as u32;
    let (width, height, viewport_height) = (pixels(frame.width()), pixels(frame.height()), pixels(viewport.height()));

    let mut digest = std::hash::DefaultHasher::new();
    (map, width, height, viewport_height).hash(&mut digest);
    for camera in &cameras {
        format!("{:?}", camera.0).hash(&mut digest);
    }
    for (joints, skin, place, view) in &characters {
        let floats = joints.matrices.iter().flat_map(|m| m.to_cols_array()).chain(place.to_matrix().to_cols_array());
        floats.chain(skin.positions.iter().flat_map(|p| p.to_array())).for_each(|f| f.to_bits().hash(&mut digest));
        format!("{:?}", view.0).hash(&mut digest);
    }
    let digest = digest.finish();
    if overlay.digest == Some(digest) {
        return;
    }
    // The guide is a centred crop of the view: the view's focal length, the guide's pixels.
    let (Ok(mut camera), Ok(view)) =
        (scene.camera(Slot(0), width, height), scene.camera(Slot(0), width, viewport_height))
    else {
        return;
    };
    camera.focal = view.focal;
    let data = scene.frame_through(Slot(0), camera);
    (overlay.pending, overlay.digest) = (Some(map_image(map, &data)), Some(digest));
    overlay.drawn += 1;
    redraw.write(RequestRedraw);
}

/// Puts the map worked out this frame in its image (one image, changed in place) and
/// names it to egui.
fn hand_the_overlay_to_egui(
    mut overlay: ResMut<ConditioningOverlay>,
    mut images: ResMut<Assets<Image>>,
    mut textures: ResMut<bevy_egui::EguiUserTextures>,
) {
    let Some(image) = overlay.pending.take() else { return };
    if overlay.image == Handle::default() {
        overlay.image = images.add(image);
    } else if images.insert(overlay.image.id(), image).is_err() {
        return;
    }
    overlay.shown = Some(textures.add_image(bevy_egui::EguiTextureHandle::Weak(overlay.image.id())));
}

/// The map as a picture to lay over the view: the OpenPose drawing with its black left out,
/// depth and normals a little see-through (sRGB, alpha not premultiplied).
fn map_image(map: ConditioningMap, data: &crate::editor::present::data::DataFrame) -> Image {
    use bevy::render::render_resource::{Extent3d, TextureDimension, TextureFormat};
    let passes = data.passes();
    let rgba: Vec<[u8; 4]> = match map {
        ConditioningMap::OpenPose => {
            let drawing = openpose_drawing(passes.width, passes.height, &people(&data.camera, &passes, &data.figures));
            drawing.pixels().map(|p| [p.0[0], p.0[1], p.0[2], if p.0 == [0; 3] { 0 } else { 255 }]).collect()
        }
        ConditioningMap::Depth => inverse_depth(&passes).pixels().map(|p| [p.0[0], p.0[0], p.0[0], 230]).collect(),
        ConditioningMap::Normal => normal_map(&passes).pixels().map(|p| [p.0[0], p.0[1], p.0[2], 230]).collect(),
    };
    let size = Extent3d { width: passes.width, height: passes.height, depth_or_array_layers: 1 };
    let usage = bevy::asset::RenderAssetUsages::RENDER_WORLD;
    Image::new(size, TextureDimension::D2, rgba.concat(), TextureFormat::Rgba8UnormSrgb, usage)
}
