//! The materials of an exported glTF: each asset material with its factors, alpha and
//! sidedness, and its textures embedded as PNG images (each image once, each sampler once;
//! `KHR_texture_transform` where a texture is transformed); a plain material per tint.

use std::collections::HashMap;

use serde_json::{Value, json};

use marionette_rig::material::{AlphaMode, Material, Sampler, TextureRef, Wrap};
use marionette_rig::{Picture, SkinTexture};

/// The `extras` key that marks a material as a character's tint (not a material of its own).
pub const TINT_MARK: &str = "marionette_tint";

/// The file's materials, textures, images and samplers, filled as characters are written.
#[derive(Default)]
pub struct Materials {
    pub materials: Vec<Value>,
    pub textures: Vec<Value>,
    pub images: Vec<Value>,
    pub samplers: Vec<Value>,
    image_of: HashMap<String, usize>,
    sampler_of: HashMap<Sampler, usize>,
    /// Whether a texture is transformed (the extension is then used).
    pub transformed: bool,
    /// Whether a material is unlit (`KHR_materials_unlit` is then used).
    pub unlit: bool,
}

impl Materials {
    /// A plain material of colour `tint`, marked as the character's tint (`extras`), so
    /// that reading the file back gives a surface without a material again.
    pub fn tint(&mut self, name: &str, tint: [f32; 3]) -> usize {
        self.materials.push(json!({
            "name": name,
            "pbrMetallicRoughness": { "baseColorFactor": [tint[0], tint[1], tint[2], 1.0],
                "metallicFactor": 0.0, "roughnessFactor": 0.75 },
            "extras": { TINT_MARK: true },
        }));
        self.materials.len() - 1
    }

    /// `m` as a glTF material; `view` stores bytes as a buffer view and returns its index.
    /// A texture whose image cannot be read or encoded is left out.
    pub fn material(&mut self, m: &Material, view: &mut dyn FnMut(&[u8]) -> usize) -> usize {
        let mut pbr = json!({
            "baseColorFactor": m.base_color,
            "metallicFactor": m.metallic,
            "roughnessFactor": m.roughness,
        });
        if let Some(info) = self.texture_info(&m.base_color_texture, view) {
            pbr["baseColorTexture"] = info;
        }
        if let Some(info) = self.texture_info(&m.metallic_roughness_texture, view) {
            pbr["metallicRoughnessTexture"] = info;
        }
        let mut out = json!({ "name": m.name, "pbrMetallicRoughness": pbr });
        if let Some(mut info) = self.texture_info(&m.normal_texture, view) {
            info["scale"] = json!(m.normal_scale);
            out["normalTexture"] = info;
        }
        if m.emissive != [0.0; 3] {
            out["emissiveFactor"] = json!(m.emissive);
        }
        if let Some(info) = self.texture_info(&m.emissive_texture, view) {
            out["emissiveTexture"] = info;
        }
        match m.alpha {
            AlphaMode::Opaque => {}
            AlphaMode::Mask(cutoff) => {
                out["alphaMode"] = json!("MASK");
                out["alphaCutoff"] = json!(cutoff);
            }
            AlphaMode::Blend => out["alphaMode"] = json!("BLEND"),
        }
        if m.double_sided {
            out["doubleSided"] = json!(true);
        }
        if m.unlit {
            out["extensions"] = json!({ "KHR_materials_unlit": {} });
            self.unlit = true;
        }
        self.materials.push(out);
        self.materials.len() - 1
    }

    /// A texture reference (`{ index, extensions }`), its image and sampler written once.
    fn texture_info(&mut self, t: &Option<TextureRef>, view: &mut dyn FnMut(&[u8]) -> usize) -> Option<Value> {
        let t = t.as_ref()?;
        let image = self.image(&t.image, view)?;
        let sampler = *self.sampler_of.entry(t.sampler).or_insert_with(|| {
            self.samplers.push(sampler_json(&t.sampler));
            self.samplers.len() - 1
        });
        self.textures.push(json!({ "source": image, "sampler": sampler }));
        let mut info = json!({ "index": self.textures.len() - 1 });
        if t.transform != Default::default() {
            self.transformed = true;
            let tr = t.transform;
            info["extensions"] = json!({ "KHR_texture_transform": {
                "offset": tr.offset.to_array(), "rotation": tr.rotation, "scale": tr.scale.to_array() } });
        }
        Some(info)
    }

    /// The image of `texture` as a PNG in the buffer (once per image).
    fn image(&mut self, texture: &SkinTexture, view: &mut dyn FnMut(&[u8]) -> usize) -> Option<usize> {
        let key = match texture {
            SkinTexture::File(path) => path.display().to_string(),
            SkinTexture::Picture { key, .. } => key.clone(),
        };
        if let Some(&image) = self.image_of.get(&key) {
            return Some(image);
        }
        let png = png_of(texture)?;
        let view = view(&png);
        self.images.push(json!({ "bufferView": view, "mimeType": "image/png" }));
        self.image_of.insert(key, self.images.len() - 1);
        Some(self.images.len() - 1)
    }
}

/// A texture's pixels as PNG bytes (a BMP file read now, or the image its file held).
fn png_of(texture: &SkinTexture) -> Option<Vec<u8>> {
    let picture = match texture {
        SkinTexture::File(path) => {
            let bytes = super::error::read_file(path).ok()?;
            std::sync::Arc::new(super::bmp::decode_bmp(&bytes, path).ok()?)
        }
        SkinTexture::Picture { picture, .. } => picture.clone(),
    };
    let Picture { width, height, pixels } = &*picture;
    let image = image::RgbaImage::from_raw(*width, *height, pixels.clone())?;
    let mut png = Vec::new();
    image.write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png).ok()?;
    Some(png)
}

fn sampler_json(s: &Sampler) -> Value {
    let wrap = |w| match w {
        Wrap::Repeat => 10497,
        Wrap::Mirror => 33648,
        Wrap::Clamp => 33071,
    };
    json!({
        "magFilter": if s.nearest_mag { 9728 } else { 9729 },
        "minFilter": if s.nearest_min { 9728 } else { 9729 },
        "wrapS": wrap(s.wrap_u),
        "wrapT": wrap(s.wrap_v),
    })
}
