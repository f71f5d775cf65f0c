//! The stage: a floor with a subtle grid, a sun that casts shadows, an ambient fill, up to
//! three lamps, the background; all as the scene's `StageDoc` says, one a slot (each scene
//! drawn in a frame has its own, on its render layer).

use bevy::light::{CascadeShadowConfig, CascadeShadowConfigBuilder, DirectionalLightShadowMap, ShadowFilteringMethod};
use bevy::prelude::*;

use crate::editor::state::StageSettings;
use crate::editor::state::camera::OrbitCamera;
use crate::formats::scene::StageDoc;
use crate::scene::Slot;

/// The sky (clear) colour.
pub const SKY: Color =
    Color::srgb(crate::formats::stage::SKY[0], crate::formats::stage::SKY[1], crate::formats::stage::SKY[2]);

#[derive(Component)]
pub struct Floor;

/// The floor's corners in the world as `transform` places its mesh.
pub fn floor_corners(transform: &Transform) -> [Vec3; 4] {
    let half = FLOOR_SIZE / 2.0;
    [(-half, -half), (half, -half), (half, half), (-half, half)]
        .map(|(x, z)| transform.transform_point(Vec3::new(x, 0.0, z)))
}

/// The side of the floor mesh (metres) before it is scaled to the scene.
const FLOOR_SIZE: f32 = 40.0;

/// How far a slot's floor and grid reach from the origin, and the grid's spacing: at least
/// 10 m, and twice the farthest character (a grid of about 40 lines each way); on the slot's
/// camera.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct StageExtent {
    pub half: f32,
    pub step: f32,
}

impl Default for StageExtent {
    fn default() -> Self {
        Self::reaching(0.0)
    }
}

impl StageExtent {
    /// The extent for characters reaching `reach` metres from the origin.
    pub fn reaching(reach: f32) -> Self {
        let half = (2.0 * reach).max(10.0);
        // At most 20 lines a side, on a round spacing (0.5, 1, 2, 5, 10, 20, ... metres).
        let raw = half / 20.0;
        let decade = 10f32.powf(raw.log10().floor());
        let step = [1.0, 2.0, 5.0, 10.0].into_iter().map(|m| m * decade).find(|&s| s >= raw).unwrap_or(raw);
        Self { half, step: step.max(0.5) }
    }
}

/// Sizes each slot's floor and grid to its characters whenever one moves or deforms
/// (reads skin bounds and placements; writes the slot camera's `StageExtent`, the floor's
/// scale).
pub fn fit_stage_to_scene(
    characters: Query<(&crate::scene::Character, &crate::scene::Placement, &Slot)>,
    changed: Query<(), Or<(Changed<bevy::camera::primitives::Aabb>, Changed<crate::scene::Placement>)>>,
    bounds: Query<&bevy::camera::primitives::Aabb>,
    mut cameras: Query<(&Slot, Ref<DrawnStage>, &mut StageExtent), With<OrbitCamera>>,
    mut floors: Query<(&Slot, &mut Transform), With<Floor>>,
) {
    let anything_moved = !changed.is_empty();
    for (slot, stage, mut extent) in &mut cameras {
        if !anything_moved && !stage.is_changed() {
            continue;
        }
        let reach = characters
            .iter()
            .filter(|c| c.2 == slot)
            .filter_map(|(character, placement, _)| {
                let aabb = bounds.get(character.skins.first()?.entity).ok()?;
                let m = placement.to_mat4();
                let (a, b) = (Vec3::from(aabb.min()), Vec3::from(aabb.max()));
                Some(
                    [a, b, Vec3::new(a.x, 0.0, b.z), Vec3::new(b.x, 0.0, a.z)]
                        .map(|c| m.transform_point3(c))
                        .into_iter()
                        .map(|p| p.x.abs().max(p.z.abs()))
                        .fold(0.0f32, f32::max),
                )
            })
            .fold(0.0f32, f32::max);
        let wanted = match stage.0.floor_size {
            Some(size) => StageExtent::reaching(size / 4.0),
            None => StageExtent::reaching(reach),
        };
        if *extent != wanted {
            *extent = wanted;
            let side = stage.0.floor_size.unwrap_or(2.0 * wanted.half) / FLOOR_SIZE;
            for (_, mut floor) in floors.iter_mut().filter(|f| f.0 == slot) {
                floor.scale = Vec3::new(side, 1.0, side);
            }
        }
    }
}

/// The sun's shadow map for a picture of `width` × `height` pixels: a cascade's side the
/// power of two at or above the picture's longer side, from 512 to 2048 (the window's).
pub fn shadow_map_for(width: u32, height: u32) -> DirectionalLightShadowMap {
    DirectionalLightShadowMap { size: width.max(height).next_power_of_two().clamp(512, 2048) as usize }
}

/// How far from what it looks at a camera may be for Bevy's default shadow cascades (the
/// first to 10 m, shadows to 150 m): people seen whole.
pub const PEOPLE_CAMERA_DISTANCE: f32 = 10.0;

/// The sun's shadow cascades for a camera `camera_distance` from what it looks at: Bevy's
/// defaults up to [`PEOPLE_CAMERA_DISTANCE`], and beyond it all their bounds scaled with the
/// distance, so that what the camera frames keeps the shadows a person has. With the
/// defaults the Khronos fox (155 units long, framed from farther than that) was shadowed
/// only where it came within 150 units of the camera: a patch by its front legs. (The
/// floor's size plays no part: a large floor under people keeps their sharp shadows.)
pub fn sun_shadow_cascades(camera_distance: f32) -> CascadeShadowConfig {
    let scale = (camera_distance / PEOPLE_CAMERA_DISTANCE).max(1.0);
    let people = CascadeShadowConfigBuilder::default();
    CascadeShadowConfigBuilder {
        minimum_distance: people.minimum_distance * scale,
        first_cascade_far_bound: people.first_cascade_far_bound * scale,
        maximum_distance: people.maximum_distance * scale,
        ..people
    }
    .build()
}

/// Fits each slot's sun's shadow cascades to the slot's orbit camera whenever it moves
/// (reads the `OrbitCamera`; writes the sun's `CascadeShadowConfig`).
pub fn fit_shadows_to_camera(
    cameras: Query<(&OrbitCamera, &Slot), Changed<OrbitCamera>>,
    mut suns: Query<(&mut CascadeShadowConfig, &Slot), With<Sun>>,
) {
    for (orbit, slot) in &cameras {
        for (mut cascades, _) in suns.iter_mut().filter(|s| s.1 == slot) {
            *cascades = sun_shadow_cascades(orbit.distance);
        }
    }
}

#[derive(Component)]
pub struct Sun;

/// A lamp of the stage (its index in `StageDoc::lamps`).
#[derive(Component)]
pub struct Lamp(pub usize);

/// The stage a slot draws, on the slot's camera: the editor's is its `StageSettings`
/// ([`stage_the_settings`]); a data set's render sets each slot's from its picture's scene.
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct DrawnStage(pub StageDoc);

/// What a slot's camera carries besides its lens: the slot, the stage it draws and how far
/// that reaches.
pub fn slot_camera(slot: Slot) -> impl Bundle {
    (slot.marks(), DrawnStage::default(), StageExtent::default())
}

/// The floor grid of a slot (a gizmo of its own, on the slot's layer).
#[derive(Component)]
pub struct Grid;

/// Spawns slot 0's stage (writes entities, `DirectionalLightShadowMap`).
pub fn spawn_stage(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut gizmos: ResMut<Assets<GizmoAsset>>,
) {
    commands.insert_resource(DirectionalLightShadowMap { size: 2048 });
    spawn_slot_stage(&mut commands, &mut meshes, &mut materials, &mut gizmos, Slot(0));
}

/// Spawns a slot's floor, grid and sun, on its layer; its camera's `DrawnStage` lights them.
pub fn spawn_slot_stage(
    commands: &mut Commands,
    meshes: &mut Assets<Mesh>,
    materials: &mut Assets<StandardMaterial>,
    gizmos: &mut Assets<GizmoAsset>,
    slot: Slot,
) {
    commands.spawn((
        Floor,
        slot.marks(),
        Mesh3d(meshes.add(Plane3d::default().mesh().size(FLOOR_SIZE, FLOOR_SIZE))),
        MeshMaterial3d(materials.add(StandardMaterial { perceptual_roughness: 0.95, ..default() })),
        Transform::default(),
    ));
    commands.spawn((Grid, slot.marks(), Gizmo { handle: gizmos.add(GizmoAsset::default()), ..default() }));
    commands.spawn((Sun, slot.marks(), DirectionalLight::default(), Transform::default()));
}

/// Gives slot 0's camera the editor's stage whenever it changes (reads `StageSettings`;
/// writes `DrawnStage`).
pub fn stage_the_settings(
    settings: Res<StageSettings>,
    mut cameras: Query<(&Slot, &mut DrawnStage), With<OrbitCamera>>,
) {
    for (slot, mut drawn) in &mut cameras {
        if *slot == Slot(0) && drawn.0 != settings.0 {
            drawn.0 = settings.0.clone();
        }
    }
}

/// Linear RGB as a colour.
fn linear([r, g, b]: [f32; 3]) -> Color {
    Color::linear_rgb(r, g, b)
}

/// The render puts a gradient or a picture behind its pictures once captured: a stage with
/// one clears to nothing.
#[derive(Resource)]
pub struct BackgroundAfterCapture;

/// Applies each slot's stage whenever it changes: the floor (shown, height, size, colour),
/// the sun (direction, light, shadows), the lamps (each the entity of the last stage's lamp
/// in its place where that was of its kind), and on every camera of the slot the ambient
/// fill, the clear colour and the shadows' filter (reads `DrawnStage`, `StageExtent`; writes
/// floor, sun, lamps, cameras).
#[allow(clippy::too_many_arguments)]
pub fn apply_stage_settings(
    mut commands: Commands,
    stages: Query<(&Slot, Ref<DrawnStage>, &StageExtent), With<OrbitCamera>>,
    mut cameras: Query<(Entity, &Slot, &mut Camera, Option<&ShadowFilteringMethod>), With<Camera3d>>,
    added: Query<(), Added<Camera3d>>,
    mut floors: Query<(&Slot, &mut Visibility, &mut Transform, &MeshMaterial3d<StandardMaterial>), With<Floor>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut suns: Query<(&Slot, &mut DirectionalLight, &mut Transform), (With<Sun>, Without<Floor>)>,
    lamps: Query<(Entity, &Slot, &Lamp, Has<SpotLight>)>,
    after_capture: Option<Res<BackgroundAfterCapture>>,
) {
    for (&slot, stage, extent) in &stages {
        if !stage.is_changed() && added.is_empty() {
            continue;
        }
        let stage = &stage.0;
        for (_, mut visibility, mut transform, material) in floors.iter_mut().filter(|f| *f.0 == slot) {
            *visibility = if stage.floor { Visibility::Inherited } else { Visibility::Hidden };
            transform.translation.y = stage.floor_height;
            let side = stage.floor_size.unwrap_or(2.0 * extent.half) / FLOOR_SIZE;
            transform.scale = Vec3::new(side, 1.0, side);
            if let Some(mut m) = materials.get_mut(&material.0) {
                let [r, g, b] = stage.floor_color;
                m.base_color = Color::srgb(r, g, b);
            }
        }
        for (_, mut sun, mut transform) in suns.iter_mut().filter(|s| *s.0 == slot) {
            sun.illuminance = stage.sun.illuminance;
            sun.color = linear(stage.sun.color);
            sun.shadow_maps_enabled = stage.shadows;
            *transform =
                Transform::from_translation(stage.sun.toward()).looking_at(Vec3::ZERO, sun_up(stage.sun.toward()));
        }
        light_lamps(&mut commands, stage, lamps.iter().filter(|l| *l.1 == slot).map(|(e, _, l, s)| (e, l.0, s)), slot);
        let ambient =
            AmbientLight { color: linear(stage.ambient.color), brightness: stage.ambient.brightness, ..default() };
        use crate::formats::scene::BackgroundDoc::{Gradient, Image};
        let behind = after_capture.is_some() && matches!(stage.background, Gradient { .. } | Image { .. });
        let ([r, g, b], alpha) = if behind { ([0.0; 3], 0.0) } else { stage.background.at(0.5) };
        let filter = match stage.soft_shadows {
            true => ShadowFilteringMethod::Gaussian,
            false => ShadowFilteringMethod::Hardware2x2,
        };
        for (entity, _, mut camera, now) in cameras.iter_mut().filter(|c| *c.1 == slot) {
            camera.clear_color = ClearColorConfig::Custom(Color::srgba(r, g, b, alpha));
            let mut entity = commands.entity(entity);
            entity.insert(ambient.clone());
            if now != Some(&filter) {
                entity.insert(filter);
            }
        }
    }
}

/// Lights the stage's lamps in a slot: each of `lamps` (entity, place, spot) kept where the
/// stage has a lamp of its kind in its place, else despawned; the others spawned.
fn light_lamps(
    commands: &mut Commands,
    stage: &StageDoc,
    lamps: impl Iterator<Item = (Entity, usize, bool)>,
    slot: Slot,
) {
    let wanted = &stage.lamps[..stage.lamps.len().min(crate::formats::scene::MAX_LAMPS)];
    let mut placed = vec![false; wanted.len()];
    for (entity, place, spot) in lamps {
        match wanted.get(place).filter(|l| l.spot.is_some() == spot && !placed[place]) {
            Some(doc) => {
                placed[place] = true;
                light_lamp(&mut commands.entity(entity), doc);
            }
            None => commands.entity(entity).despawn(),
        }
    }
    for (i, doc) in wanted.iter().enumerate().filter(|&(i, _)| !placed[i]) {
        light_lamp(&mut commands.spawn((Lamp(i), slot.marks())), doc);
    }
}

/// An up direction for a light looking along `toward` (any but `toward` itself).
fn sun_up(toward: Vec3) -> Vec3 {
    if toward.cross(Vec3::Y).length_squared() < 1e-6 { Vec3::Z } else { Vec3::Y }
}

/// Gives a lamp its light and place: a point light, or a spot light aimed at its point.
fn light_lamp(entity: &mut EntityCommands, lamp: &crate::formats::scene::LampDoc) {
    let (color, intensity, shadows_enabled) = (linear(lamp.color), lamp.intensity, lamp.shadows);
    let at = Transform::from_translation(lamp.position);
    match lamp.spot {
        Some(spot) => {
            let aim = if spot.aim.distance_squared(lamp.position) < 1e-8 { lamp.position - Vec3::Y } else { spot.aim };
            let outer = spot.angle.to_radians();
            let light = SpotLight {
                color,
                intensity,
                shadow_maps_enabled: shadows_enabled,
                range: 40.0,
                outer_angle: outer,
                inner_angle: outer * 0.8,
                ..default()
            };
            entity.insert((light, at.looking_at(aim, sun_up(aim - lamp.position))));
        }
        None => {
            let light = PointLight { color, intensity, shadow_maps_enabled: shadows_enabled, range: 40.0, ..default() };
            entity.insert((light, at));
        }
    }
}

/// Draws each slot's floor grid anew when its stage or extent changes (reads
/// `DrawnStage`, `StageExtent`; writes the grid's gizmo).
pub fn draw_grids(
    stages: Query<
        (&Slot, &DrawnStage, &StageExtent),
        (With<OrbitCamera>, Or<(Changed<DrawnStage>, Changed<StageExtent>)>),
    >,
    grids: Query<(&Slot, &Gizmo), With<Grid>>,
    mut gizmos: ResMut<Assets<GizmoAsset>>,
) {
    for (slot, stage, extent) in &stages {
        for (_, grid) in grids.iter().filter(|g| g.0 == slot) {
            let Some(mut lines) = gizmos.get_mut(&grid.handle) else { continue };
            lines.clear();
            if stage.0.floor {
                let y = stage.0.floor_height + 0.001;
                let color = Color::srgba(0.2, 0.22, 0.25, 0.5);
                let (half, step) = (extent.half, extent.step);
                let count = (half / step).round() as i32;
                for i in -count..=count {
                    let t = i as f32 * step;
                    lines.line(Vec3::new(t, y, -half), Vec3::new(t, y, half), color);
                    lines.line(Vec3::new(-half, y, t), Vec3::new(half, y, t), color);
                }
            }
        }
    }
}

/// Draws the world axes when on (reads `StageSettings`, slot 0's extent; draws gizmos).
pub fn draw_axes(
    settings: Res<StageSettings>,
    cameras: Query<(&Slot, &StageExtent), With<OrbitCamera>>,
    mut gizmos: Gizmos,
) {
    let Some((_, extent)) = cameras.iter().find(|c| *c.0 == Slot(0)) else { return };
    if settings.axes {
        gizmos.axes(Transform::from_xyz(0.0, settings.floor_height + 0.002, 0.0), 0.5 * extent.step / 0.5);
    }
}

/// The viewport's gradient or picture background: a quad of the gradient's colours, or
/// showing the picture, far behind everything, carried by the camera (the render instead
/// puts the exact background behind its picture once captured).
#[derive(Component)]
pub struct Backdrop;

/// How far behind the camera's focus the backdrop stands (within every lens's far plane).
const BACKDROP_DEPTH: f32 = 800.0;

/// The reference picture the backdrop shows: its file, its pixels, its width over height.
#[derive(Default)]
pub struct BackdropPicture(Option<(std::path::PathBuf, Handle<Image>, f32)>);

/// Keeps a backdrop on the orbit camera showing the stage's gradient or picture, sized to
/// its lens (a picture fitted inside the view or filling it); hidden for any other
/// background, or a picture that does not load (said once) (reads `StageSettings`, the
/// camera; writes the backdrop, `Messages`).
#[allow(clippy::too_many_arguments)]
pub fn show_gradient_backdrop(
    mut commands: Commands,
    settings: Res<StageSettings>,
    cameras: Query<(Entity, Ref<OrbitCamera>, Option<&Projection>)>,
    mut backdrops: Query<
        (Entity, &mut Transform, &mut Visibility, &Mesh3d, &MeshMaterial3d<StandardMaterial>),
        With<Backdrop>,
    >,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut images: ResMut<Assets<Image>>,
    mut picture: Local<BackdropPicture>,
    mut messages: ResMut<crate::editor::state::Messages>,
) {
    let Some((camera, orbit, projection)) = cameras.iter().next() else { return };
    let view_aspect = match projection {
        Some(Projection::Perspective(p)) => p.aspect_ratio,
        _ => 16.0 / 9.0,
    };
    let white = [1.0; 3];
    let (top, bottom, texture, width_over_height) = match &settings.background {
        crate::formats::scene::BackgroundDoc::Gradient { top, bottom } => (*top, *bottom, None, 8.0),
        crate::formats::scene::BackgroundDoc::Image { path, fill } => {
            if picture.0.as_ref().is_none_or(|(p, ..)| p != path) {
                picture.0 = match image::open(path) {
                    Ok(pixels) => {
                        let aspect = pixels.width() as f32 / pixels.height().max(1) as f32;
                        let image = Image::from_dynamic(
                            pixels,
                            true,
                            bevy::asset::RenderAssetUsages::RENDER_WORLD | bevy::asset::RenderAssetUsages::MAIN_WORLD,
                        );
                        Some((path.clone(), images.add(image), aspect))
                    }
                    Err(e) => {
                        if settings.is_changed() && !path.as_os_str().is_empty() {
                            messages.push(format!("{}: {e}", path.display()));
                        }
                        None
                    }
                };
            }
            match &picture.0 {
                // Fitted inside the view, or covering it: the height's share of the view's.
                Some((_, handle, aspect)) => {
                    let widths = view_aspect / aspect;
                    let share = if *fill { widths.max(1.0) } else { widths.min(1.0) };
                    (white, white, Some((handle.clone(), share)), *aspect)
                }
                None => {
                    backdrops.iter_mut().for_each(|(.., mut v, _, _)| *v = Visibility::Hidden);
                    return;
                }
            }
        }
        _ => {
            backdrops.iter_mut().for_each(|(.., mut v, _, _)| *v = Visibility::Hidden);
            return;
        }
    };
    if !settings.is_changed() && !orbit.is_changed() && !backdrops.is_empty() {
        return;
    }
    let view_height = match orbit.ortho {
        Some(h) => h,
        None => 2.0 * (orbit.distance + BACKDROP_DEPTH) * (orbit.fov.to_radians() / 2.0).tan(),
    };
    let grow = texture.as_ref().map_or(1.02, |(_, grow)| *grow);
    let height = view_height * grow;
    let at = Transform::from_xyz(0.0, 0.0, -(orbit.distance + BACKDROP_DEPTH)).with_scale(Vec3::new(
        height * width_over_height,
        height,
        1.0,
    ));
    let colors = |c: [f32; 3]| {
        let linear = Color::srgb(c[0], c[1], c[2]).to_linear();
        [linear.red, linear.green, linear.blue, 1.0]
    };
    // Rectangle vertices: top right, top left, bottom left, bottom right.
    let vertex_colors = vec![colors(top), colors(top), colors(bottom), colors(bottom)];
    let texture = texture.map(|(handle, _)| handle);
    if let Some((_, mut transform, mut visibility, mesh, material)) = backdrops.iter_mut().next() {
        *transform = at;
        *visibility = Visibility::Inherited;
        if let Some(mut m) = meshes.get_mut(&mesh.0) {
            m.insert_attribute(Mesh::ATTRIBUTE_COLOR, vertex_colors);
        }
        if let Some(mut m) = materials.get_mut(&material.0)
            && m.base_color_texture != texture
        {
            m.base_color_texture = texture;
        }
        return;
    }
    let mesh = Mesh::from(Rectangle::new(1.0, 1.0)).with_inserted_attribute(Mesh::ATTRIBUTE_COLOR, vertex_colors);
    let material = StandardMaterial { unlit: true, base_color_texture: texture, ..default() };
    let backdrop = commands
        .spawn((
            Backdrop,
            Mesh3d(meshes.add(mesh)),
            MeshMaterial3d(materials.add(material)),
            at,
            bevy::light::NotShadowCaster,
            bevy::light::NotShadowReceiver,
        ))
        .id();
    commands.entity(camera).add_child(backdrop);
}
