//! The stage: a floor with a subtle grid, a sun that casts shadows, ambient light.

use bevy::light::{DirectionalLightShadowMap, light_consts};
use bevy::prelude::*;

/// Scene-wide view settings: the scene file's own type (floor, shadows, axes, floor
/// height), held as a resource.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq, Deref, DerefMut)]
pub struct StageSettings(pub crate::formats::scene::StageDoc);

/// The sky (clear) colour.
pub const SKY: Color = Color::srgb(0.62, 0.7, 0.78);

#[derive(Component)]
pub struct Floor;

/// The side of the floor mesh (metres) before it is scaled to the scene.
const FLOOR_SIZE: f32 = 40.0;

/// How far floor and grid reach from the origin, and the grid's spacing: at least 10 m,
/// and twice the farthest character (a grid of about 40 lines each way).
#[derive(Resource, Clone, Copy, Debug, PartialEq)]
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

/// Sizes floor and grid to the characters whenever one moves or deforms (reads skin
/// bounds and placements; writes `StageExtent`, the floor's scale).
pub fn fit_stage_to_scene(
    characters: Query<(&crate::scene::Character, &crate::scene::Placement)>,
    changed: Query<(), Or<(Changed<bevy::camera::primitives::Aabb>, Changed<crate::scene::Placement>)>>,
    bounds: Query<&bevy::camera::primitives::Aabb>,
    mut extent: ResMut<StageExtent>,
    mut floors: Query<&mut Transform, With<Floor>>,
) {
    if changed.is_empty() {
        return;
    }
    let reach = characters
        .iter()
        .filter_map(|(character, placement)| {
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
    let wanted = StageExtent::reaching(reach);
    if *extent != wanted {
        *extent = wanted;
        for mut floor in &mut floors {
            floor.scale = Vec3::new(2.0 * wanted.half / FLOOR_SIZE, 1.0, 2.0 * wanted.half / FLOOR_SIZE);
        }
    }
}

#[derive(Component)]
pub struct Sun;

/// Spawns floor and lights (writes entities).
pub fn spawn_stage(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    settings: Res<StageSettings>,
) {
    commands.insert_resource(DirectionalLightShadowMap { size: 2048 });
    commands.insert_resource(GlobalAmbientLight { color: Color::WHITE, brightness: 350.0, ..default() });
    commands.spawn((
        Floor,
        Mesh3d(meshes.add(Plane3d::default().mesh().size(FLOOR_SIZE, FLOOR_SIZE))),
        MeshMaterial3d(materials.add(StandardMaterial {
            base_color: Color::srgb(0.55, 0.57, 0.6),
            perceptual_roughness: 0.95,
            ..default()
        })),
        Transform::from_xyz(0.0, settings.floor_height, 0.0),
    ));
    commands.spawn((
        Sun,
        DirectionalLight {
            illuminance: light_consts::lux::OVERCAST_DAY * 4.0,
            shadow_maps_enabled: settings.shadows,
            ..default()
        },
        Transform::from_xyz(2.0, 4.0, 3.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
}

/// Applies floor/shadow switches (reads `StageSettings`; writes floor visibility, sun).
pub fn apply_stage_settings(
    settings: Res<StageSettings>,
    mut floors: Query<(&mut Visibility, &mut Transform), With<Floor>>,
    mut suns: Query<&mut DirectionalLight, With<Sun>>,
) {
    if !settings.is_changed() {
        return;
    }
    for (mut visibility, mut transform) in &mut floors {
        *visibility = if settings.floor { Visibility::Inherited } else { Visibility::Hidden };
        transform.translation.y = settings.floor_height;
    }
    for mut sun in &mut suns {
        sun.shadow_maps_enabled = settings.shadows;
    }
}

/// Draws the floor grid and, when on, the world axes (reads `StageSettings`; draws gizmos).
pub fn draw_grid_and_axes(settings: Res<StageSettings>, extent: Res<StageExtent>, mut gizmos: Gizmos) {
    if settings.floor {
        let y = settings.floor_height + 0.001;
        let color = Color::srgba(0.2, 0.22, 0.25, 0.5);
        let (half, step) = (extent.half, extent.step);
        let lines = (half / step).round() as i32;
        for i in -lines..=lines {
            let t = i as f32 * step;
            gizmos.line(Vec3::new(t, y, -half), Vec3::new(t, y, half), color);
            gizmos.line(Vec3::new(-half, y, t), Vec3::new(half, y, t), color);
        }
    }
    if settings.axes {
        gizmos.axes(Transform::from_xyz(0.0, settings.floor_height + 0.002, 0.0), 0.5 * extent.step / 0.5);
    }
}
