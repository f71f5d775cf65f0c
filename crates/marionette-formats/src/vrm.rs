//! VRM avatars (`.vrm`): glTF files whose `VRMC_vrm` (VRM 1.0) or `VRM` (VRM 0.x) extension
//! names the humanoid bones and the expressions (blend shape groups in 0.x). Read from the
//! file's JSON beside the glTF import, which reads the rest as any glTF file.

use serde_json::Value;

use marionette_rig::humanoid::HumanBone;

/// What a VRM extension adds to a glTF file: each humanoid bone's node, and the
/// expressions.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Vrm {
    pub bones: Vec<(HumanBone, usize)>,
    pub expressions: Vec<VrmExpression>,
}

/// A named expression: morph targets set to weights (0–1).
#[derive(Debug, Clone, PartialEq)]
pub struct VrmExpression {
    pub name: String,
    pub binds: Vec<MorphBind>,
}

/// One morph target an expression sets: on the mesh of a node (VRM 1.0) or on a mesh
/// (VRM 0.x), target `index`, to `weight`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MorphBind {
    pub on: BindTarget,
    pub index: usize,
    pub weight: f32,
}

/// What a morph bind names.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BindTarget {
    Node(usize),
    Mesh(usize),
}

/// The VRM extension of a glTF file's JSON, if it has one; an error names the JSON path of
/// what is malformed.
pub fn read(json: &Value) -> Result<Option<Vrm>, String> {
    let extensions = json.get("extensions");
    if let Some(vrm) = extensions.and_then(|e| e.get("VRMC_vrm")) {
        return read_1(vrm).map(Some);
    }
    if let Some(vrm) = extensions.and_then(|e| e.get("VRM")) {
        return read_0(vrm).map(Some);
    }
    Ok(None)
}

/// VRM 1.0: `humanoid.humanBones.{bone}.node`, `expressions.{preset,custom}.{name}.morphTargetBinds`.
fn read_1(vrm: &Value) -> Result<Vrm, String> {
    let mut out = Vrm::default();
    let bones = match vrm.pointer("/humanoid/humanBones") {
        None => None,
        Some(v) => {
            Some(v.as_object().ok_or("at $.extensions.VRMC_vrm.humanoid.humanBones: expected an object of bones")?)
        }
    };
    let metacarpal = bones.is_some_and(|b| b.keys().any(|k| k.ends_with("ThumbMetacarpal")));
    let upper_chest = bones.is_some_and(|b| b.contains_key("upperChest"));
    for (name, bone) in bones.into_iter().flatten() {
        let at = format!("$.extensions.VRMC_vrm.humanoid.humanBones.{name}.node");
        let node = index(bone.get("node"), &at)?;
        if let Some(b) = human_bone(name, metacarpal, upper_chest) {
            out.bones.push((b, node));
        }
    }
    for group in ["preset", "custom"] {
        let Some(expressions) = vrm.pointer(&format!("/expressions/{group}")).and_then(Value::as_object) else {
            continue;
        };
        for (name, expression) in expressions {
            let at = format!("$.extensions.VRMC_vrm.expressions.{group}.{name}.morphTargetBinds");
            let mut binds = Vec::new();
            for (k, bind) in list(expression.get("morphTargetBinds"), &at)?.iter().enumerate() {
                let at = format!("{at}[{k}]");
                let node = index(bind.get("node"), &format!("{at}.node"))?;
                let target = index(bind.get("index"), &format!("{at}.index"))?;
                let weight = weight(bind.get("weight"), 1.0, &format!("{at}.weight"))?;
                binds.push(MorphBind { on: BindTarget::Node(node), index: target, weight });
            }
            out.expressions.push(VrmExpression { name: name.clone(), binds });
        }
    }
    Ok(out)
}

/// VRM 0.x: `humanoid.humanBones[{bone, node}]`, `blendShapeMaster.blendShapeGroups[{name,
/// presetName, binds[{mesh, index, weight (0–100)}]}]`.
fn read_0(vrm: &Value) -> Result<Vrm, String> {
    let mut out = Vrm::default();
    let at = "$.extensions.VRM.humanoid.humanBones";
    let bones = list(vrm.pointer("/humanoid/humanBones"), at)?;
    let upper_chest = bones.iter().any(|b| b.get("bone").and_then(Value::as_str) == Some("upperChest"));
    for (k, bone) in bones.iter().enumerate() {
        let node = index(bone.get("node"), &format!("{at}[{k}].node"))?;
        let name = bone.get("bone").and_then(Value::as_str);
        if let Some(b) = name.and_then(|name| human_bone(name, false, upper_chest)) {
            out.bones.push((b, node));
        }
    }
    let at = "$.extensions.VRM.blendShapeMaster.blendShapeGroups";
    for (g, group) in list(vrm.pointer("/blendShapeMaster/blendShapeGroups"), at)?.iter().enumerate() {
        let preset = group.get("presetName").and_then(Value::as_str).filter(|p| !p.is_empty() && *p != "unknown");
        let name = preset.or_else(|| group.get("name").and_then(Value::as_str)).unwrap_or("expression").to_string();
        let mut binds = Vec::new();
        for (k, bind) in list(group.get("binds"), &format!("{at}[{g}].binds"))?.iter().enumerate() {
            let at = format!("{at}[{g}].binds[{k}]");
            let mesh = index(bind.get("mesh"), &format!("{at}.mesh"))?;
            let target = index(bind.get("index"), &format!("{at}.index"))?;
            let weight = weight(bind.get("weight"), 100.0, &format!("{at}.weight"))? / 100.0;
            binds.push(MorphBind { on: BindTarget::Mesh(mesh), index: target, weight });
        }
        out.expressions.push(VrmExpression { name, binds });
    }
    Ok(out)
}

impl Vrm {
    /// Whether every node and mesh it names is in a file of `nodes` nodes and `meshes`
    /// meshes; the first that is not, named.
    pub fn check(&self, nodes: usize, meshes: usize) -> Result<(), String> {
        for &(bone, node) in &self.bones {
            if node >= nodes {
                return Err(format!(
                    "at $.extensions (VRM humanoid bone {bone:?}): expected a node index below {nodes}, found {node}"
                ));
            }
        }
        for e in &self.expressions {
            for bind in &e.binds {
                let (what, index, count) = match bind.on {
                    BindTarget::Node(n) => ("node", n, nodes),
                    BindTarget::Mesh(m) => ("mesh", m, meshes),
                };
                if index >= count {
                    return Err(format!(
                        "at $.extensions (VRM expression `{}`): expected a {what} index below {count}, found {index}",
                        e.name
                    ));
                }
            }
        }
        Ok(())
    }
}

/// The standard bone a VRM bone name is: VRM 1.0 names the thumb's joints metacarpal,
/// proximal, distal (`metacarpal` says so); 0.x proximal, intermediate, distal. `upperChest`
/// is the chest (where the arms meet) and `chest` then no bone of ours.
fn human_bone(name: &str, metacarpal: bool, upper_chest: bool) -> Option<HumanBone> {
    use HumanBone::*;
    let (left, rest) = if let Some(r) = name.strip_prefix("left") {
        (Some(true), r)
    } else if let Some(r) = name.strip_prefix("right") {
        (Some(false), r)
    } else {
        (None, name)
    };
    const FINGERS: [&str; 5] = ["Thumb", "Index", "Middle", "Ring", "Little"];
    if let Some(left) = left
        && let Some(f) = FINGERS.iter().position(|f| rest.starts_with(f))
    {
        let phalanx = &rest[FINGERS[f].len()..];
        let k = match (f == 0 && metacarpal, phalanx) {
            (true, "Metacarpal") => 0,
            (true, "Proximal") => 1,
            (true, "Distal") => 2,
            (false, "Proximal") => 0,
            (false, "Intermediate") => 1,
            (false, "Distal") => 2,
            _ => return None,
        };
        return Some(HumanBone::finger(left, f, k));
    }
    let side = |l: HumanBone, r: HumanBone| left.map(|left| if left { l } else { r });
    match rest {
        "hips" if left.is_none() => Some(Hips),
        "spine" if left.is_none() => Some(Spine),
        "upperChest" if left.is_none() => Some(Chest),
        "chest" if left.is_none() && !upper_chest => Some(Chest),
        "neck" if left.is_none() => Some(Neck),
        "head" if left.is_none() => Some(Head),
        "Shoulder" => side(LeftShoulder, RightShoulder),
        "UpperArm" => side(LeftUpperArm, RightUpperArm),
        "LowerArm" => side(LeftLowerArm, RightLowerArm),
        "Hand" => side(LeftHand, RightHand),
        "UpperLeg" => side(LeftUpperLeg, RightUpperLeg),
        "LowerLeg" => side(LeftLowerLeg, RightLowerLeg),
        "Foot" => side(LeftFoot, RightFoot),
        "Toes" => side(LeftToes, RightToes),
        _ => None,
    }
}

fn index(v: Option<&Value>, at: &str) -> Result<usize, String> {
    v.and_then(Value::as_u64)
        .and_then(|n| usize::try_from(n).ok())
        .ok_or_else(|| format!("at {at}: expected an index (a whole number from 0)"))
}

fn weight(v: Option<&Value>, most: f64, at: &str) -> Result<f32, String> {
    match v {
        None => Ok(most as f32),
        Some(v) => v
            .as_f64()
            .filter(|w| w.is_finite() && (0.0..=most).contains(w))
            .map(|w| w as f32)
            .ok_or_else(|| format!("at {at}: expected a weight from 0 to {most}")),
    }
}

fn list<'v>(v: Option<&'v Value>, at: &str) -> Result<&'v [Value], String> {
    match v {
        None => Ok(&[]),
        Some(v) => v.as_array().map(Vec::as_slice).ok_or_else(|| format!("at {at}: expected an array")),
    }
}
