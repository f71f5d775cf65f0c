//! The material every skin is drawn with: `StandardMaterial` (white, so vertex colours show
//! as they are) extended with a fragment shader that lights each triangle with its own
//! normal, from the derivatives of the world position. The skinning system then writes
//! only shared vertex positions (and colours when they change): no unshared corners and
//! no normals on the CPU or in the upload.

use bevy::asset::embedded_asset;
use bevy::pbr::{ExtendedMaterial, MaterialExtension, MaterialPlugin};
use bevy::prelude::*;
use bevy::render::render_resource::AsBindGroup;
use bevy::shader::ShaderRef;

/// The extension: no data of its own, only the flat-normal fragment shader.
#[derive(Asset, AsBindGroup, Reflect, Debug, Clone, Default)]
pub struct FlatNormals {}

impl MaterialExtension for FlatNormals {
    fn fragment_shader() -> ShaderRef {
        "embedded://marionette/editor/present/flat_normals.wgsl".into()
    }
}

/// The skin material type.
pub type SkinMaterialAsset = ExtendedMaterial<StandardMaterial, FlatNormals>;

/// One material for every skin without a texture.
#[derive(Resource)]
pub struct SkinMaterial(pub Handle<SkinMaterialAsset>);

/// The materials of textured skins, by texture (a file's path, or the key of an image a
/// character's file holds; loaded once).
#[derive(Resource, Default)]
pub struct TexturedSkinMaterials(pub std::collections::HashMap<String, Handle<SkinMaterialAsset>>);

/// The skin material with `image` as its base colour texture.
pub fn textured_material(
    image: &crate::formats::bmp::Rgba,
    images: &mut Assets<Image>,
    materials: &mut Assets<SkinMaterialAsset>,
) -> Handle<SkinMaterialAsset> {
    let size =
        bevy::render::render_resource::Extent3d { width: image.width, height: image.height, depth_or_array_layers: 1 };
    let texture = Image::new(
        size,
        bevy::render::render_resource::TextureDimension::D2,
        image.pixels.clone(),
        bevy::render::render_resource::TextureFormat::Rgba8UnormSrgb,
        bevy::asset::RenderAssetUsages::RENDER_WORLD,
    );
    let base = StandardMaterial {
        base_color: Color::WHITE,
        base_color_texture: Some(images.add(texture)),
        perceptual_roughness: 0.75,
        ..default()
    };
    materials.add(ExtendedMaterial { base, extension: FlatNormals {} })
}

pub struct SkinMaterialPlugin;

impl Plugin for SkinMaterialPlugin {
    fn build(&self, app: &mut App) {
        embedded_asset!(app, "flat_normals.wgsl");
        app.init_resource::<TexturedSkinMaterials>()
            .add_plugins(MaterialPlugin::<SkinMaterialAsset>::default())
            .add_systems(Startup, setup_skin_material);
    }
}

fn setup_skin_material(mut commands: Commands, mut materials: ResMut<Assets<SkinMaterialAsset>>) {
    let base = StandardMaterial { base_color: Color::WHITE, perceptual_roughness: 0.75, ..default() };
    commands.insert_resource(SkinMaterial(materials.add(ExtendedMaterial { base, extension: FlatNormals {} })));
}
