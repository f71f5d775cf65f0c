//! A glTF part's looks: its primitives' materials (base colour factor and texture,
//! metallic-roughness, normal map, emission, alpha mode and cutoff, double-sidedness;
//! samplers and `KHR_texture_transform`), the surface each primitive is, and the
//! vertices' texture coordinates (`TEXCOORD_0`) and colours (`COLOR_0`). Images are decoded
//! once per file.

use std::borrow::Cow;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

use glam::Vec2;

use marionette_rig::material::{AlphaMode, Material, Sampler, Surface, TextureRef, TextureTransform, Wrap};
use marionette_rig::{Picture, Skin, SkinTexture};

/// The decoded images of a file, by image index (none: it could not be read, and a
/// warning said why).
#[derive(Default)]
pub struct Images(HashMap<usize, Option<SkinTexture>>);

/// What a part's primitives look like, gathered as they are read.
#[derive(Default)]
pub struct Looks {
    /// Our material of each of the file's materials.
    ours: HashMap<usize, usize>,
    pub materials: Vec<Material>,
    pub surfaces: Vec<Surface>,
    texcoords: Vec<Vec2>,
    colors: Vec<[f32; 4]>,
    textured: bool,
    colored: bool,
    normal_mapped: bool,
}

/// Where a file's bytes are: its buffers and its path (for images beside it).
pub struct Source<'a> {
    pub buffers: &'a [Cow<'a, [u8]>],
    pub path: &'a Path,
}

impl Looks {
    /// Adds a primitive whose vertices start at `first` (`count` of them) and whose
    /// triangles are `triangles`: its material, its surface, its coordinates and colours.
    #[allow(clippy::too_many_arguments)]
    pub fn add(
        &mut self,
        source: &Source,
        images: &mut Images,
        primitive: &gltf::Primitive,
        at: &str,
        first: usize,
        count: usize,
        triangles: std::ops::Range<u32>,
        warnings: &mut Vec<String>,
    ) -> Result<(), String> {
        let material = match primitive.material().index() {
            None => None,
            // Our own export's tint: a surface without a material of its own.
            Some(_) if is_tint(&primitive.material()) => None,
            Some(index) => Some(match self.ours.get(&index) {
                Some(&ours) => ours,
                None => {
                    let material = material(source, images, &primitive.material(), warnings)?;
                    self.textured |= material.textures().next().is_some();
                    self.normal_mapped |= material.normal_texture.is_some();
                    self.materials.push(material);
                    self.ours.insert(index, self.materials.len() - 1);
                    self.materials.len() - 1
                }
            }),
        };
        let vertices = first as u32..(first + count) as u32;
        marionette_rig::material::push_surface(&mut self.surfaces, Surface { vertices, triangles, material });
        let reader = primitive.reader(|b| source.buffers.get(b.index()).map(|d| &**d));
        self.texcoords.resize(first, Vec2::ZERO);
        if let Some(uv) = reader.read_tex_coords(0) {
            self.texcoords.extend(uv.into_f32().take(count).map(Vec2::from));
            if let Some(v) = self.texcoords[first..].iter().position(|t| !t.is_finite()) {
                return Err(format!("{at}.attributes.TEXCOORD_0: expected finite numbers, found vertex {v}'s"));
            }
        }
        self.colors.resize(first, [1.0; 4]);
        if let Some(colors) = reader.read_colors(0) {
            self.colored = true;
            self.colors.extend(colors.into_rgba_f32().take(count));
            if let Some(v) = self.colors[first..].iter().position(|c| !c.iter().all(|x| x.is_finite())) {
                return Err(format!("{at}.attributes.COLOR_0: expected finite numbers, found vertex {v}'s"));
            }
        }
        Ok(())
    }

    /// Gives `skin` the coordinates and colours (when a material is textured, when a
    /// primitive has colours), one per vertex, and keeps its normals only when a material
    /// has a normal map.
    pub fn finish(&mut self, skin: &mut Skin) {
        if !self.normal_mapped {
            skin.normals = Vec::new();
        }
        let n = skin.bind_positions.len();
        if self.textured {
            self.texcoords.resize(n, Vec2::ZERO);
            skin.texcoords = std::mem::take(&mut self.texcoords);
        }
        if self.colored {
            self.colors.resize(n, [1.0; 4]);
            skin.colors = std::mem::take(&mut self.colors);
        }
    }
}

/// A file's material as ours. Factors that are not finite are refused.
fn material(
    source: &Source,
    images: &mut Images,
    m: &gltf::Material,
    warnings: &mut Vec<String>,
) -> Result<Material, String> {
    let at = format!("at $.materials[{}]", m.index().unwrap_or(0));
    let pbr = m.pbr_metallic_roughness();
    let strength = m.emissive_strength().unwrap_or(1.0);
    let emissive = m.emissive_factor().map(|e| e * strength);
    let numbers = [pbr.metallic_factor(), pbr.roughness_factor(), m.alpha_cutoff().unwrap_or(0.5), strength];
    if !(numbers.iter().chain(&emissive).chain(&pbr.base_color_factor()).all(|x| x.is_finite())) {
        return Err(format!("{at}: expected finite factors, found one that is not"));
    }
    let mut texture = |info: Option<(gltf::Texture, u32, Option<TextureTransform>)>, what: &str| {
        let (texture, set, transform) = info?;
        if set != 0 {
            warnings.push(format!(
                "{}: {at}: its {what} texture uses TEXCOORD_{set}, read as TEXCOORD_0",
                source.path.display()
            ));
        }
        let image = decoded(source, images, &texture, warnings)?;
        Some(TextureRef { image, sampler: sampler(&texture.sampler()), transform: transform.unwrap_or_default() })
    };
    let normal = m.normal_texture();
    let normal_scale = normal.as_ref().map_or(1.0, |n| n.scale());
    Ok(Material {
        name: m.name().map_or_else(|| format!("material {}", m.index().unwrap_or(0)), str::to_string),
        base_color: pbr.base_color_factor(),
        base_color_texture: texture(pbr.base_color_texture().map(info), "base colour"),
        metallic: pbr.metallic_factor(),
        roughness: pbr.roughness_factor(),
        metallic_roughness_texture: texture(pbr.metallic_roughness_texture().map(info), "metallic-roughness"),
        normal_texture: texture(normal.map(|n| (n.texture(), n.tex_coord(), None)), "normal"),
        normal_scale: if normal_scale.is_finite() { normal_scale } else { 1.0 },
        emissive,
        emissive_texture: texture(m.emissive_texture().map(info), "emissive"),
        alpha: match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask(m.alpha_cutoff().unwrap_or(0.5)),
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        },
        double_sided: m.double_sided(),
        unlit: m.unlit(),
    })
}

fn sampler(s: &gltf::texture::Sampler) -> Sampler {
    use gltf::texture::{MagFilter, MinFilter, WrappingMode};
    let wrap = |w| match w {
        WrappingMode::Repeat => Wrap::Repeat,
        WrappingMode::MirroredRepeat => Wrap::Mirror,
        WrappingMode::ClampToEdge => Wrap::Clamp,
    };
    Sampler {
        wrap_u: wrap(s.wrap_s()),
        wrap_v: wrap(s.wrap_t()),
        nearest_mag: s.mag_filter() == Some(MagFilter::Nearest),
        nearest_min: matches!(
            s.min_filter(),
            Some(MinFilter::Nearest | MinFilter::NearestMipmapNearest | MinFilter::NearestMipmapLinear)
        ),
    }
}

/// A texture's image, decoded once per file (PNG or JPEG, from the file's buffers, a
/// `data:` URI or a file beside it); a warning and none when it cannot be read.
fn decoded(
    source: &Source,
    images: &mut Images,
    texture: &gltf::Texture,
    warnings: &mut Vec<String>,
) -> Option<SkinTexture> {
    let image = texture.source();
    images
        .0
        .entry(image.index())
        .or_insert_with(|| {
            let at = format!("{}: at $.images[{}]", source.path.display(), image.index());
            let bytes = match image.source() {
                gltf::image::Source::View { view, .. } => source
                    .buffers
                    .get(view.buffer().index())
                    .and_then(|b| b.get(view.offset()..view.offset() + view.length()))
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| "its bytes cannot be read".to_string()),
                gltf::image::Source::Uri { uri, .. } => super::uri::bytes(source.path, uri),
            };
            match bytes.and_then(|b| image::load_from_memory(&b).map_err(|e| e.to_string())) {
                Ok(decoded) => {
                    let rgba = decoded.to_rgba8();
                    let picture = Picture { width: rgba.width(), height: rgba.height(), pixels: rgba.into_raw() };
                    Some(SkinTexture::Picture { key: at, picture: Arc::new(picture) })
                }
                Err(e) => {
                    warnings.push(format!("{at}: the texture is not shown ({e})"));
                    None
                }
            }
        })
        .clone()
}

/// A texture reference's texture, coordinate set and `KHR_texture_transform` (finite).
fn info(i: gltf::texture::Info<'_>) -> (gltf::Texture<'_>, u32, Option<TextureTransform>) {
    let transform = i.texture_transform().map(|t| TextureTransform {
        offset: Vec2::from(t.offset()),
        rotation: t.rotation(),
        scale: Vec2::from(t.scale()),
    });
    let set = i.texture_transform().and_then(|t| t.tex_coord()).unwrap_or(i.tex_coord());
    (i.texture(), set, transform.filter(|t| t.offset.is_finite() && t.rotation.is_finite() && t.scale.is_finite()))
}

/// Whether a material is the tint Marionette's export gives a surface without a material.
fn is_tint(m: &gltf::Material) -> bool {
    m.extras()
        .as_ref()
        .and_then(|raw| serde_json::from_str::<serde_json::Value>(raw.get()).ok())
        .is_some_and(|v| v.get(super::gltf_out_materials::TINT_MARK) == Some(&serde_json::Value::Bool(true)))
}
