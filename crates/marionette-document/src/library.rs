//! The asset library: characters (and their clips, SMPL bodies, glTF and FBX parts) loaded by
//! source, once, and shared by every scene character made from them. No Bevy: the editor
//! keeps one as a resource, `export` and `render` make their own.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use marionette_formats::scene::{BindingDoc, CharacterDoc, SourceDoc};
use marionette_formats::{FormatError, load_character};
use marionette_rig::CharacterAsset;
use marionette_rig::smpl::{Clip, SmplModel};

/// Loaded characters by source, shared by every scene character made from them.
#[derive(Default)]
pub struct AssetLibrary {
    cache: HashMap<SourceDoc, Arc<CharacterAsset>>,
    smpl: HashMap<PathBuf, SmplSet>,
    bound: HashMap<(SourceDoc, BindingDoc), Arc<CharacterAsset>>,
    keyframe_clips: HashMap<PathBuf, Arc<marionette_rig::anim::Clip>>,
    parts: HashMap<PathBuf, Vec<LoadedPart>>,
    humanoids: HashMap<SourceDoc, Arc<marionette_rig::humanoid::HumanoidMap>>,
    /// Motions carried from one character onto another, by what they were worked out from.
    pub(crate) retargetings: HashMap<String, Arc<Retargeting>>,
}

/// A retargeted clip and what retargeting did ([`crate::retarget::retarget`]).
pub struct Retargeting {
    pub clip: marionette_rig::anim::Clip,
    pub report: marionette_rig::retarget::Retargeted,
    /// Target leg length over the source's.
    pub leg_ratio: f32,
    /// The source's frames as sampled.
    pub source_frames: Vec<marionette_rig::retarget::Frame>,
    /// The floors (model space) of the source's motion and of the target.
    pub floors: (f32, f32),
}

/// One part of a glTF or FBX file, loaded: its asset, its clips and its morph weights.
#[derive(Clone)]
pub struct LoadedPart {
    pub asset: Arc<CharacterAsset>,
    pub clips: Arc<[marionette_rig::node_clip::NodeClip]>,
    pub morph_weights: Vec<f32>,
}

/// A copy of `asset` whose weights come from its bones at rest (by `binding`); when heat
/// binding fails, smooth weights and a warning that says so.
pub fn rebind(asset: &CharacterAsset, binding: BindingDoc) -> CharacterAsset {
    use marionette_rig::bind::{Binding, bind_to_skeleton};
    let mut out = asset.clone();
    let (skeleton, skin) = (&asset.skeleton, &asset.skin);
    out.skin.weights = match bind_to_skeleton(skeleton, &skin.bind_positions, &skin.triangles, binding) {
        Ok(weights) => weights,
        Err(e) => {
            out.warnings.push(format!("{}: {e}; smooth weights instead", asset.name));
            bind_to_skeleton(skeleton, &skin.bind_positions, &skin.triangles, Binding::Smooth)
                .expect("smooth binding cannot fail")
        }
    };
    out.warnings.push(format!("weights computed ({binding:?}) from the bones"));
    out
}

/// An SMPL model and the clips of its folder.
#[derive(Clone)]
pub struct SmplSet {
    pub model: Arc<SmplModel>,
    pub clips: Vec<(String, Arc<Clip>)>,
    /// What the loader fixed (normalised weight rows).
    pub warnings: Vec<String>,
}

impl AssetLibrary {
    /// The character of `source` with the humanoid map found from its skeleton (none
    /// assigned by hand), each worked out once.
    pub fn rig(
        &mut self,
        source: &SourceDoc,
    ) -> Result<(Arc<CharacterAsset>, Arc<marionette_rig::humanoid::HumanoidMap>), FormatError> {
        let asset = self.load(source)?;
        let map = match self.humanoids.get(source) {
            Some(map) => map.clone(),
            None => {
                // Found from the skeleton alone (none assigned by hand).
                let map = Arc::new(marionette_rig::humanoid::of_asset(&asset).map(|d| d.map).unwrap_or_default());
                self.humanoids.insert(source.clone(), map.clone());
                map
            }
        };
        Ok((asset, map))
    }

    /// The character of `source`, loaded once.
    pub fn load(&mut self, source: &SourceDoc) -> Result<Arc<CharacterAsset>, FormatError> {
        if let Some(asset) = self.cache.get(source) {
            return Ok(asset.clone());
        }
        let asset = Arc::new(match source {
            SourceDoc::Embedded(name) if name == "puppet" => marionette_formats::puppet::embedded_puppet(),
            SourceDoc::Embedded(name) => {
                return Err(FormatError::other(
                    Path::new(name),
                    "expected a built-in character (`puppet`), found an unknown name",
                ));
            }
            // An SMPL folder is read once, for the body and for its clips.
            SourceDoc::File(dir) if marionette_formats::smpl::is_smpl_dir(dir) => {
                let set = self.smpl(dir)?;
                let name = dir.file_stem().and_then(|s| s.to_str()).unwrap_or("smpl");
                let mut asset = set.model.asset(name, &[]).map_err(|e| FormatError::rig(dir, e))?;
                asset.warnings = set.warnings;
                asset
            }
            SourceDoc::File(path) if marionette_formats::has_parts(path) => {
                return Ok(self.file_part(path, 0)?.asset);
            }
            SourceDoc::Part(path, n) => return Ok(self.file_part(path, *n)?.asset),
            SourceDoc::File(path) => load_character(path)?,
        });
        self.cache.insert(source.clone(), asset.clone());
        Ok(asset)
    }

    /// Part `n` of the glTF or FBX file at `path` (the file read once).
    pub fn file_part(&mut self, path: &Path, n: usize) -> Result<LoadedPart, FormatError> {
        let parts = self.file_parts(path)?;
        parts.get(n).cloned().ok_or_else(|| {
            FormatError::other(
                path,
                format!("expected character {} of the file, found {} characters", n.saturating_add(1), parts.len()),
            )
        })
    }

    /// Every part of the glTF or FBX file at `path` (the file read once).
    pub fn file_parts(&mut self, path: &Path) -> Result<&[LoadedPart], FormatError> {
        if !self.parts.contains_key(path) {
            let parts = marionette_formats::load_parts(path)?
                .into_iter()
                .map(|c| LoadedPart { asset: Arc::new(c.asset), clips: c.clips.into(), morph_weights: c.morph_weights })
                .collect();
            self.parts.insert(path.to_path_buf(), parts);
        }
        Ok(&self.parts[path])
    }

    /// The sources of a path: one per part of a glTF or FBX file (its first as `File`, the
    /// others as `Part`), or the path itself.
    pub fn sources_of(&mut self, path: &Path) -> Vec<SourceDoc> {
        let file = SourceDoc::File(path.to_path_buf());
        if !marionette_formats::has_parts(path) {
            return vec![file];
        }
        let count = self.file_parts(path).map_or(1, <[LoadedPart]>::len);
        std::iter::once(file).chain((1..count).map(|n| SourceDoc::Part(path.to_path_buf(), n))).collect()
    }

    /// A new character's document for `source`: its name, the motion a BVH brings, a white
    /// tint where its own materials colour it, and the morph weights its file sets.
    pub fn new_character_doc(&mut self, source: SourceDoc, asset: &CharacterAsset) -> CharacterDoc {
        let mut doc = CharacterDoc { anim: own_motion(&source), ..CharacterDoc::new(source, asset.name.clone()) };
        if asset.surfaces().iter().all(|s| s.material.is_some()) {
            doc.view.tint = [1.0; 3];
        }
        if let Some(part) = self.part_of_source(&doc.source)
            && part.morph_weights.iter().any(|&w| w != 0.0)
        {
            doc.morphs = part.morph_weights;
        }
        doc
    }

    /// The glTF or FBX part a source names, if it is one.
    pub fn part_of_source(&mut self, source: &SourceDoc) -> Option<LoadedPart> {
        match source {
            SourceDoc::File(p) if marionette_formats::has_parts(p) => self.file_part(p, 0).ok(),
            SourceDoc::Part(p, n) => self.file_part(p, *n).ok(),
            _ => None,
        }
    }

    /// The keyframed clip (`.anim`) at `path`, read once.
    pub fn keyframe_clip(&mut self, path: &Path) -> Result<Arc<marionette_rig::anim::Clip>, FormatError> {
        if let Some(clip) = self.keyframe_clips.get(path) {
            return Ok(clip.clone());
        }
        let clip = Arc::new(marionette_formats::load_clip(path)?);
        self.keyframe_clips.insert(path.to_path_buf(), clip.clone());
        Ok(clip)
    }

    /// The character of `source` with weights computed from its bones (cached).
    pub fn load_bound(
        &mut self,
        source: &SourceDoc,
        binding: Option<BindingDoc>,
    ) -> Result<Arc<CharacterAsset>, FormatError> {
        let asset = self.load(source)?;
        let Some(binding) = binding else { return Ok(asset) };
        if let Some(bound) = self.bound.get(&(source.clone(), binding)) {
            return Ok(bound.clone());
        }
        let bound = Arc::new(rebind(&asset, binding));
        self.bound.insert((source.clone(), binding), bound.clone());
        Ok(bound)
    }

    /// The asset a character document stands for: its source, bound as it asks, an SMPL
    /// body shaped by its β.
    pub fn shaped(&mut self, c: &marionette_formats::scene::CharacterDoc) -> Result<Arc<CharacterAsset>, FormatError> {
        let mut asset = self.load_bound(&c.source, c.binding)?;
        if let (Some(smpl), SourceDoc::File(dir)) = (&c.smpl, &c.source)
            && !smpl.betas.is_empty()
        {
            let set = self.smpl(dir)?;
            asset = Arc::new(set.model.asset(&c.name, &smpl.betas).map_err(|e| FormatError::rig(dir, e))?);
        }
        Ok(asset)
    }

    /// The SMPL model and clips of a folder, loaded once.
    pub fn smpl(&mut self, dir: &Path) -> Result<SmplSet, FormatError> {
        if let Some(set) = self.smpl.get(dir) {
            return Ok(set.clone());
        }
        let (model, warnings) = marionette_formats::smpl::load_smpl_dir(dir)?;
        let n = model.skeleton.len();
        let clips = marionette_formats::smpl::clip_paths(dir)
            .into_iter()
            .map(|p| {
                let clip = marionette_formats::smpl::parse_clip(marionette_formats::error::open(&p)?, &p, n)?;
                Ok((p.file_name().map(|f| f.to_string_lossy().into_owned()).unwrap_or_default(), Arc::new(clip)))
            })
            .collect::<Result<Vec<_>, FormatError>>()?;
        let set = SmplSet { model: Arc::new(model), clips, warnings };
        self.smpl.insert(dir.to_path_buf(), set.clone());
        Ok(set)
    }
}

/// The motion a source brings with it: a BVH file plays its own clip.
pub fn own_motion(source: &SourceDoc) -> Option<marionette_formats::scene::AnimDoc> {
    match source {
        SourceDoc::File(p) if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bvh")) => {
            Some(marionette_formats::scene::AnimDoc::of(p.clone()))
        }
        _ => None,
    }
}
