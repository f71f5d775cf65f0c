//! glTF 2.0 read on its own, from the spec, in double precision: the test's reference for
//! what a file's meshes look like at rest and at any time of any animation. It shares no
//! code with Marionette's importer (no `gltf` crate): GLB chunks, accessors (strides,
//! offsets, normalised integers, sparse), node transforms, step/linear/slerp/cubic-spline
//! sampling (glTF 2.0 Appendix C), morph targets and skinning
//! (`Σ w · global(joint) · inverseBind(joint) · v`).

use glam::{DMat4, DQuat, DVec3};
use serde_json::Value;

/// An accessor's elements, each its components.
type Elements = Vec<Vec<f64>>;

/// A glTF file: its JSON and its buffers.
pub struct SpecFile {
    pub json: Value,
    buffers: Vec<Vec<u8>>,
}

fn index(v: &Value) -> usize {
    v.as_u64().expect("an index") as usize
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().map(|a| a.iter().map(|x| x.as_f64().expect("a number")).collect()).unwrap_or_default()
}

impl SpecFile {
    /// A `.glb` file (one JSON chunk, one binary chunk).
    pub fn read(path: &std::path::Path) -> Self {
        let glb = std::fs::read(path).unwrap();
        let u32_at = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().unwrap()) as usize;
        assert_eq!(&glb[0..4], b"glTF");
        let json_len = u32_at(12);
        let json: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
        let bin_at = 20 + json_len;
        let bin = if bin_at + 8 <= glb.len() { glb[bin_at + 8..bin_at + 8 + u32_at(bin_at)].to_vec() } else { vec![] };
        Self { json, buffers: vec![bin] }
    }

    /// An accessor's elements as doubles (normalised integers mapped as the spec says),
    /// `components` per element.
    pub fn accessor(&self, a: usize) -> Vec<Vec<f64>> {
        let a = &self.json["accessors"][a];
        let count = index(&a["count"]);
        let components = match a["type"].as_str().unwrap() {
            "SCALAR" => 1,
            "VEC2" => 2,
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT4" => 16,
            other => panic!("type {other}"),
        };
        let kind = index(&a["componentType"]);
        let normalized = a["normalized"].as_bool().unwrap_or(false);
        let mut out = vec![vec![0.0; components]; count];
        if let Some(view) = a.get("bufferView") {
            let offset = a["byteOffset"].as_u64().unwrap_or(0) as usize;
            self.read_elements(index(view), offset, kind, normalized, components, &mut out);
        }
        if let Some(sparse) = a.get("sparse") {
            let n = index(&sparse["count"]);
            let mut at = vec![vec![0.0]; n];
            let i = &sparse["indices"];
            self.read_elements(
                index(&i["bufferView"]),
                i["byteOffset"].as_u64().unwrap_or(0) as usize,
                index(&i["componentType"]),
                false,
                1,
                &mut at,
            );
            let mut values = vec![vec![0.0; components]; n];
            let v = &sparse["values"];
            let offset = v["byteOffset"].as_u64().unwrap_or(0) as usize;
            self.read_elements(index(&v["bufferView"]), offset, kind, normalized, components, &mut values);
            for (i, value) in at.iter().zip(values) {
                out[i[0] as usize] = value;
            }
        }
        out
    }

    fn read_elements(
        &self,
        view: usize,
        offset: usize,
        kind: usize,
        normalized: bool,
        components: usize,
        out: &mut [Vec<f64>],
    ) {
        let view = &self.json["bufferViews"][view];
        let buffer = &self.buffers[index(&view["buffer"])];
        let start = view["byteOffset"].as_u64().unwrap_or(0) as usize + offset;
        let size = match kind {
            5120 | 5121 => 1,
            5122 | 5123 => 2,
            5125 | 5126 => 4,
            other => panic!("component type {other}"),
        };
        // Matrices of 1- and 2-byte components pad their columns; none are read here.
        let stride = view["byteStride"].as_u64().map_or(size * components, |s| s as usize);
        for (e, element) in out.iter_mut().enumerate() {
            for (c, value) in element.iter_mut().enumerate() {
                let at = start + e * stride + c * size;
                let b = &buffer[at..at + size];
                *value = match (kind, normalized) {
                    (5126, _) => f64::from(f32::from_le_bytes(b.try_into().unwrap())),
                    (5120, false) => f64::from(b[0] as i8),
                    (5121, false) => f64::from(b[0]),
                    (5122, false) => f64::from(i16::from_le_bytes(b.try_into().unwrap())),
                    (5123, false) => f64::from(u16::from_le_bytes(b.try_into().unwrap())),
                    (5125, _) => f64::from(u32::from_le_bytes(b.try_into().unwrap())),
                    (5120, true) => (f64::from(b[0] as i8) / 127.0).max(-1.0),
                    (5121, true) => f64::from(b[0]) / 255.0,
                    (5122, true) => (f64::from(i16::from_le_bytes(b.try_into().unwrap())) / 32767.0).max(-1.0),
                    (5123, true) => f64::from(u16::from_le_bytes(b.try_into().unwrap())) / 65535.0,
                    other => panic!("component {other:?}"),
                };
            }
        }
    }

    pub fn nodes(&self) -> &[Value] {
        self.json["nodes"].as_array().map_or(&[], Vec::as_slice)
    }

    pub fn animations(&self) -> &[Value] {
        self.json["animations"].as_array().map_or(&[], Vec::as_slice)
    }

    /// An animation's length: its last key time.
    pub fn duration(&self, animation: usize) -> f64 {
        let a = &self.animations()[animation];
        a["samplers"]
            .as_array()
            .unwrap()
            .iter()
            .map(|s| self.accessor(index(&s["input"])).last().map_or(0.0, |k| k[0]))
            .fold(0.0, f64::max)
    }

    /// Every node's global matrix, posed by `animation` at `time` seconds (the nodes' own
    /// transforms without one).
    pub fn node_globals(&self, animation: Option<(usize, f64)>) -> Vec<DMat4> {
        let nodes = self.nodes();
        let mut trs: Vec<Trs> = nodes.iter().map(Trs::of).collect();
        let mut weights: Vec<Option<Vec<f64>>> = vec![None; nodes.len()];
        if let Some((a, t)) = animation {
            self.apply(a, t, &mut trs, &mut weights);
        }
        self.globals(&trs)
    }

    /// Every mesh node's triangle vertices, in node order (primitives in order), posed by
    /// `animation` at `time` seconds (the nodes' own transforms without one).
    pub fn posed(&self, animation: Option<(usize, f64)>) -> Vec<DVec3> {
        let nodes = self.nodes();
        let mut trs: Vec<Trs> = nodes.iter().map(Trs::of).collect();
        let mut weights: Vec<Option<Vec<f64>>> = nodes.iter().map(|n| n.get("weights").map(numbers)).collect();
        if let Some((a, t)) = animation {
            self.apply(a, t, &mut trs, &mut weights);
        }
        let globals = self.globals(&trs);
        let mut out = Vec::new();
        for (n, node) in nodes.iter().enumerate() {
            let Some(mesh) = node.get("mesh").map(index) else { continue };
            let mesh = &self.json["meshes"][mesh];
            let weights = weights[n].clone().or_else(|| mesh.get("weights").map(numbers)).unwrap_or_default();
            let joints: Option<Vec<DMat4>> = node.get("skin").map(|s| {
                let skin = &self.json["skins"][index(s)];
                let ibm = skin.get("inverseBindMatrices").map(|a| self.accessor(index(a)));
                skin["joints"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .enumerate()
                    .map(|(k, j)| {
                        let inverse = ibm.as_ref().map_or(DMat4::IDENTITY, |m| DMat4::from_cols_slice(&m[k]));
                        globals[index(j)] * inverse
                    })
                    .collect()
            });
            for p in mesh["primitives"].as_array().unwrap() {
                if p["mode"].as_u64().unwrap_or(4) != 4 {
                    continue;
                }
                let attribute = |name: &str| p["attributes"].get(name).map(|a| self.accessor(index(a)));
                let mut positions: Vec<DVec3> =
                    attribute("POSITION").unwrap().iter().map(|v| DVec3::from_slice(v)).collect();
                for (k, target) in p["targets"].as_array().into_iter().flatten().enumerate() {
                    let w = weights.get(k).copied().unwrap_or(0.0);
                    if let (Some(d), true) = (target.get("POSITION"), w != 0.0) {
                        for (v, d) in positions.iter_mut().zip(self.accessor(index(d))) {
                            *v += w * DVec3::from_slice(&d);
                        }
                    }
                }
                match &joints {
                    Some(joints) => {
                        let (js, ws) = (attribute("JOINTS_0").unwrap(), attribute("WEIGHTS_0").unwrap());
                        let sets: Vec<(Elements, Elements)> = std::iter::once((js, ws))
                            .chain((1..).map_while(|s| {
                                Some((attribute(&format!("JOINTS_{s}"))?, attribute(&format!("WEIGHTS_{s}"))?))
                            }))
                            .collect();
                        for (v, position) in positions.iter().enumerate() {
                            let mut sum = DVec3::ZERO;
                            for (js, ws) in &sets {
                                for c in 0..4 {
                                    sum += ws[v][c] * joints[js[v][c] as usize].transform_point3(*position);
                                }
                            }
                            out.push(sum);
                        }
                    }
                    None => out.extend(positions.iter().map(|&v| globals[n].transform_point3(v))),
                }
            }
        }
        out
    }

    /// Every node's global matrix from its transform and its parents'.
    fn globals(&self, trs: &[Trs]) -> Vec<DMat4> {
        let nodes = self.nodes();
        let mut parent = vec![None; nodes.len()];
        for (n, node) in nodes.iter().enumerate() {
            for c in node["children"].as_array().into_iter().flatten() {
                parent[index(c)] = Some(n);
            }
        }
        let mut out = vec![None; nodes.len()];
        fn global(n: usize, parent: &[Option<usize>], trs: &[Trs], out: &mut [Option<DMat4>]) -> DMat4 {
            if let Some(m) = out[n] {
                return m;
            }
            let up = parent[n].map_or(DMat4::IDENTITY, |p| global(p, parent, trs, out));
            let m = up * trs[n].matrix();
            out[n] = Some(m);
            m
        }
        (0..nodes.len()).map(|n| global(n, &parent, trs, &mut out)).collect()
    }

    /// Sets the keyed properties of animation `a` at time `t`.
    fn apply(&self, a: usize, t: f64, trs: &mut [Trs], weights: &mut [Option<Vec<f64>>]) {
        let animation = &self.animations()[a];
        for channel in animation["channels"].as_array().unwrap() {
            let sampler = &animation["samplers"][index(&channel["sampler"])];
            let node = index(&channel["target"]["node"]);
            let times: Vec<f64> = self.accessor(index(&sampler["input"])).iter().map(|k| k[0]).collect();
            let values = self.accessor(index(&sampler["output"]));
            let interpolation = sampler["interpolation"].as_str().unwrap_or("LINEAR");
            let path = channel["target"]["path"].as_str().unwrap();
            let value = sample(&times, &values, interpolation, path, t);
            match path {
                "translation" => trs[node].translation = DVec3::from_slice(&value),
                "rotation" => trs[node].rotation = Some(DQuat::from_slice(&value).normalize()),
                "scale" => trs[node].scale = DVec3::from_slice(&value),
                "weights" => weights[node] = Some(value),
                other => panic!("path {other}"),
            }
        }
    }
}

/// A node's transform: its matrix, or its translation, rotation and scale.
#[derive(Clone)]
struct Trs {
    matrix: Option<DMat4>,
    translation: DVec3,
    rotation: Option<DQuat>,
    scale: DVec3,
}

impl Trs {
    fn of(node: &Value) -> Self {
        let v3 = |k: &str, d: f64| node.get(k).map_or(DVec3::splat(d), |v| DVec3::from_slice(&numbers(v)));
        Self {
            matrix: node.get("matrix").map(|m| DMat4::from_cols_slice(&numbers(m))),
            translation: v3("translation", 0.0),
            // A unit quaternion, the spec says; files hold them to single precision.
            rotation: node.get("rotation").map(|r| DQuat::from_slice(&numbers(r)).normalize()),
            scale: v3("scale", 1.0),
        }
    }

    fn matrix(&self) -> DMat4 {
        self.matrix.unwrap_or_else(|| {
            let r = self.rotation.unwrap_or(DQuat::IDENTITY);
            DMat4::from_translation(self.translation) * DMat4::from_quat(r) * DMat4::from_scale(self.scale)
        })
    }
}

/// A sampler's value at `t` (glTF 2.0 Appendix C), clamped to its first and last keys.
/// Values are flat per key (a key of weights holds every target's weight).
fn sample(times: &[f64], values: &[Vec<f64>], interpolation: &str, path: &str, t: f64) -> Vec<f64> {
    let n = times.len();
    // Rows of one key: weights are one scalar per target and key.
    let per = values.len() / n / if interpolation == "CUBICSPLINE" { 3 } else { 1 };
    let key = |k: usize, part: usize| -> Vec<f64> {
        let base = if interpolation == "CUBICSPLINE" { (3 * k + part) * per } else { k * per };
        values[base..base + per].iter().flatten().copied().collect()
    };
    let value = |k: usize| key(k, 1);
    if t <= times[0] || n == 1 {
        return value(0);
    }
    if t >= times[n - 1] {
        return value(n - 1);
    }
    let k = times.iter().rposition(|&x| x <= t).unwrap();
    let dt = times[k + 1] - times[k];
    let u = (t - times[k]) / dt;
    let mix = |a: &[f64], b: &[f64], u: f64| a.iter().zip(b).map(|(a, b)| a + (b - a) * u).collect::<Vec<_>>();
    match interpolation {
        "STEP" => value(k),
        "LINEAR" if path == "rotation" => {
            let (a, b) = (DQuat::from_slice(&value(k)), DQuat::from_slice(&value(k + 1)));
            slerp(a, b, u).to_array().to_vec()
        }
        "LINEAR" => mix(&value(k), &value(k + 1), u),
        "CUBICSPLINE" => {
            let (v0, b0, a1, v1) = (value(k), key(k, 2), key(k + 1, 0), value(k + 1));
            let (u2, u3) = (u * u, u * u * u);
            let out: Vec<f64> = (0..v0.len())
                .map(|i| {
                    (2.0 * u3 - 3.0 * u2 + 1.0) * v0[i]
                        + dt * (u3 - 2.0 * u2 + u) * b0[i]
                        + (-2.0 * u3 + 3.0 * u2) * v1[i]
                        + dt * (u3 - u2) * a1[i]
                })
                .collect();
            out
        }
        other => panic!("interpolation {other}"),
    }
}

/// Spherical linear interpolation along the shorter arc (the spec's reference).
fn slerp(a: DQuat, b: DQuat, u: f64) -> DQuat {
    let mut d = a.dot(b);
    let b = if d < 0.0 {
        d = -d;
        -b
    } else {
        b
    };
    if d > 0.9995 {
        return (a * (1.0 - u) + b * u).normalize();
    }
    let theta = d.acos();
    let s = theta.sin();
    (a * (((1.0 - u) * theta).sin() / s) + b * ((u * theta).sin() / s)).normalize()
}
