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
        Mesh3d(meshes.add(Plane3d::default().mesh().size(40.0, 40.0))),
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
pub fn draw_grid_and_axes(settings: Res<StageSettings>, mut gizmos: Gizmos) {
    if settings.floor {
        let y = settings.floor_height + 0.001;
        let color = Color::srgba(0.2, 0.22, 0.25, 0.5);
        for i in -20..=20 {
            let t = i as f32 * 0.5;
            gizmos.line(Vec3::new(t, y, -10.0), Vec3::new(t, y, 10.0), color);
            gizmos.line(Vec3::new(-10.0, y, t), Vec3::new(10.0, y, t), color);
        }
    }
    if settings.axes {
        gizmos.axes(Transform::from_xyz(0.0, settings.floor_height + 0.002, 0.0), 0.5);
    }
}
