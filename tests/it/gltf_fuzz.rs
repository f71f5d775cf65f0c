//! A structure-aware glTF fuzzer: real `.glb` files (the project's Blender fixtures, the
//! hostile files' valid base and, with `MARIONETTE_DATA`, the Khronos samples) are taken
//! apart into their JSON and binary chunk; the JSON is mutated where a reader trusts it
//! (counts, offsets, strides, types, component types, indices, node children, URIs,
//! numbers to huge or non-finite), the binary chunk gets NaN, infinite and huge floats or a
//! cut, and the file is packed again. Each case replays from its seed and must meet
//! `fuzz.rs`'s oracle (no panic, an answer within 5 s, bounded memory, every rejection
//! placed), under the dev profile (overflow checks on).

use std::path::{Path, PathBuf};
use std::time::Instant;

use arbitrary::{Result as Drawn, Unstructured};
use serde_json::Value;

use crate::common::data_dir;
use crate::fuzz::{Reader, check_case, random_bytes};

/// Cases per run.
const CASES: usize = 20_000;

/// The project's own GLB files.
fn project_seeds() -> Vec<(String, Vec<u8>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    read_seeds(vec![
        root.join("tests/data/blender_arm.glb"),
        root.join("tests/data/blender_pair.glb"),
        root.join("tests/regressions/commands/gltf-clip-3e38-seconds.glb"),
    ])
}

/// Khronos samples from the data folder (BrainStem, 3 MB, is left out: a case of it takes
/// as long as a hundred others).
fn khronos_seeds() -> Vec<(String, Vec<u8>)> {
    let data = data_dir();
    let names = ["SimpleSkin", "RiggedSimple", "RiggedFigure", "CesiumMan", "Fox", "Box", "AnimatedMorphCube"];
    read_seeds(names.iter().map(|name| data.join(format!("khronos/{name}.glb"))).collect())
}

fn read_seeds(files: Vec<PathBuf>) -> Vec<(String, Vec<u8>)> {
    files
        .into_iter()
        .map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), std::fs::read(&p).unwrap()))
        .collect()
}

/// A GLB's JSON and binary chunk (the seeds are valid files).
fn unpack(glb: &[u8]) -> (Value, Vec<u8>) {
    let word = |at: usize| u32::from_le_bytes(glb[at..at + 4].try_into().unwrap()) as usize;
    let json_len = word(12);
    let json = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    let bin = if glb.len() > 28 + json_len {
        glb[28 + json_len..28 + json_len + word(20 + json_len)].to_vec()
    } else {
        Vec::new()
    };
    (json, bin)
}

fn pack(json: &Value, bin: &[u8], length_delta: i64) -> Vec<u8> {
    let mut text = serde_json::to_vec(json).unwrap();
    text.resize(text.len().next_multiple_of(4), b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + text.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend(((total as i64 + length_delta) as u32).to_le_bytes());
    out.extend((text.len() as u32).to_le_bytes());
    out.extend(0x4E4F_534Au32.to_le_bytes());
    out.extend(text);
    if !bin.is_empty() {
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(0x004E_4942u32.to_le_bytes());
        out.extend(bin);
    }
    out
}

/// Numbers that break careless readers of glTF.
const NUMBERS: &[f64] = &[
    0.0,
    -1.0,
    1.0,
    3.0,
    4.0,
    255.0,
    65535.0,
    2147483648.0,
    4294967296.0,
    9007199254740992.0,
    4611686018427387904.0,
    18446744073709551615.0,
    1e39,
    -1e39,
    3e38,
    1e-45,
    0.5,
];
const COMPONENT_TYPES: &[u64] = &[5120, 5121, 5122, 5123, 5124, 5125, 5126, 0];
const TYPES: &[&str] = &["SCALAR", "VEC2", "VEC3", "VEC4", "MAT2", "MAT3", "MAT4", "VEC5"];
const URIS: &[&str] = &[
    "/etc/passwd",
    "../../../../etc/passwd",
    "file:///etc/passwd",
    "data:application/octet-stream;base64,AAAA",
    "%2e%2e/%2e%2e/etc/passwd",
    "missing.bin",
    "/dev/zero",
    "%zz",
    "",
];

/// The paths (as JSON pointers) of every number, array and object in `value`.
fn places(value: &Value, at: String, numbers: &mut Vec<String>, objects: &mut Vec<String>) {
    match value {
        Value::Number(_) => numbers.push(at),
        Value::Array(items) => {
            for (i, v) in items.iter().enumerate() {
                places(v, format!("{at}/{i}"), numbers, objects);
            }
        }
        Value::Object(fields) => {
            objects.push(at.clone());
            for (k, v) in fields {
                places(v, format!("{at}/{k}"), numbers, objects);
            }
        }
        _ => {}
    }
}

/// An element of the array at `pointer` (none when it is missing or empty).
fn pick<'v>(json: &'v mut Value, pointer: &str, u: &mut Unstructured) -> Drawn<Option<&'v mut Value>> {
    let Some(Value::Array(items)) = json.pointer_mut(pointer) else { return Ok(None) };
    if items.is_empty() {
        return Ok(None);
    }
    let i = u.choose_index(items.len())?;
    Ok(Some(&mut items[i]))
}

fn count(json: &Value, pointer: &str) -> usize {
    json.pointer(pointer).and_then(Value::as_array).map_or(0, Vec::len)
}

/// One to three structure-aware mutations of the JSON or the binary chunk.
fn mutate(json: &mut Value, bin: &mut Vec<u8>, length_delta: &mut i64, u: &mut Unstructured) -> Drawn<()> {
    for _ in 0..u.int_in_range(1..=3)? {
        match u.int_in_range(0..=10)? {
            0 => {
                let (mut numbers, mut objects) = (Vec::new(), Vec::new());
                places(json, String::new(), &mut numbers, &mut objects);
                if !numbers.is_empty() {
                    let at = &numbers[u.choose_index(numbers.len())?];
                    let n = *u.choose(NUMBERS)?;
                    *json.pointer_mut(at).unwrap() = serde_json::Number::from_f64(n).map_or(Value::Null, Value::Number);
                    if n == 18446744073709551615.0 {
                        *json.pointer_mut(at).unwrap() = Value::from(u64::MAX);
                    }
                }
            }
            1 => {
                let ct = *u.choose(COMPONENT_TYPES)?;
                if let Some(a) = pick(json, "/accessors", u)? {
                    a["componentType"] = ct.into();
                }
            }
            2 => {
                let t = *u.choose(TYPES)?;
                let normalized: bool = u.arbitrary()?;
                if let Some(a) = pick(json, "/accessors", u)? {
                    a["type"] = t.into();
                    a["normalized"] = normalized.into();
                }
            }
            3 => {
                let stride = *u.choose(&[0u64, 1, 4, 8, 12, 16, 252, 256])?;
                let offset = *u.choose(&[0u64, 1, 3, 4, 1 << 31, u64::MAX - 3])?;
                let which: u8 = u.int_in_range(0..=2)?;
                if let Some(v) = pick(json, "/bufferViews", u)? {
                    match which {
                        0 => v["byteStride"] = stride.into(),
                        1 => v["byteOffset"] = offset.into(),
                        _ => v["byteLength"] = offset.into(),
                    }
                }
            }
            4 => {
                // A child edge anywhere: cycles, a node its own child, two parents.
                let n = count(json, "/nodes");
                if n > 0 {
                    let (from, to) = (u.choose_index(n)?, u.int_in_range(0..=n)?);
                    let node = &mut json["nodes"][from];
                    match node.get_mut("children").and_then(Value::as_array_mut) {
                        Some(children) => children.push(to.into()),
                        None => node["children"] = vec![to].into(),
                    }
                }
            }
            5 => {
                let uri = *u.choose(URIS)?;
                if let Some(b) = pick(json, "/buffers", u)? {
                    b["uri"] = uri.into();
                }
            }
            6 => {
                // An index somewhere replaced: joints, samplers, targets, attributes.
                let n = count(json, "/accessors").max(count(json, "/nodes")) + 2;
                let to = u.int_in_range(0..=n)?;
                let (mut numbers, mut objects) = (Vec::new(), Vec::new());
                places(json, String::new(), &mut numbers, &mut objects);
                let indices: Vec<&String> = numbers
                    .iter()
                    .filter(|p| {
                        [
                            "/joints/",
                            "/sampler",
                            "/node",
                            "/input",
                            "/output",
                            "/attributes/",
                            "/indices",
                            "/inverseBindMatrices",
                            "/skin",
                            "/mesh",
                            "/bufferView",
                            "/source",
                            "/nodes/",
                        ]
                        .iter()
                        .any(|k| p.contains(k))
                    })
                    .collect();
                if !indices.is_empty() {
                    let at = indices[u.choose_index(indices.len())?].clone();
                    *json.pointer_mut(&at).unwrap() = to.into();
                }
            }
            7 => {
                let (mut numbers, mut objects) = (Vec::new(), Vec::new());
                places(json, String::new(), &mut numbers, &mut objects);
                let at = &objects[u.choose_index(objects.len())?];
                if let Some(Value::Object(fields)) = json.pointer_mut(at)
                    && !fields.is_empty()
                {
                    let key = fields.keys().nth(u.choose_index(fields.len())?).unwrap().clone();
                    fields.remove(&key);
                }
            }
            8 => {
                let sparse = serde_json::json!({
                    "count": u.int_in_range(0..=5u64)?,
                    "indices": { "bufferView": u.int_in_range(0..=3u64)?, "componentType": *u.choose(COMPONENT_TYPES)? },
                    "values": { "bufferView": u.int_in_range(0..=3u64)?, "byteOffset": *u.choose(&[0u64, 4, 1 << 40])? },
                });
                if let Some(a) = pick(json, "/accessors", u)? {
                    a["sparse"] = sparse;
                }
            }
            9 if bin.len() >= 4 => {
                let at = u.choose_index(bin.len() / 4)? * 4;
                let f = *u.choose(&[f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 3e38, 0.0, -0.0, 1e-45])?;
                bin[at..at + 4].copy_from_slice(&f.to_le_bytes());
            }
            _ => match u.int_in_range(0..=2)? {
                0 => bin.truncate(u.choose_index(bin.len() + 1)?),
                1 => *length_delta = *u.choose(&[-8i64, -4, 4, 1 << 20, -(1 << 20)])?,
                _ => json["asset"]["version"] = (*u.choose(&["1.0", "2.1", "3"])?).into(),
            },
        }
    }
    Ok(())
}

#[test]
fn mutated_gltf_structure_never_panics_hangs_or_balloons_and_rejections_are_placed() {
    fuzz_structure(&project_seeds());
}

/// The same over the Khronos samples of the data folder.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn mutated_khronos_structure_never_panics_hangs_or_balloons_and_rejections_are_placed() {
    fuzz_structure(&khronos_seeds());
}

/// [`CASES`] structural mutations of `seeds` (each a valid file): none panics, hangs or
/// balloons, every rejection names its place.
fn fuzz_structure(seeds: &[(String, Vec<u8>)]) {
    for (name, bytes) in seeds {
        // Every seed reads (Box and AnimatedMorphCube have no skin: a placed rejection).
        assert!(check_case(Reader::Glb, bytes.clone()).is_ok(), "{name}");
    }
    let unpacked: Vec<(Value, Vec<u8>)> = seeds.iter().map(|(_, b)| unpack(b)).collect();
    let started = Instant::now();
    let (mut accepted, mut rejected, mut failures) = (0, 0, Vec::new());
    for case in 0..CASES {
        let k = case % seeds.len();
        let (mut json, mut bin) = unpacked[k].clone();
        let mut delta = 0;
        let noise = random_bytes(0x61c8_8647 ^ case as u64, 256);
        let _ = mutate(&mut json, &mut bin, &mut delta, &mut Unstructured::new(&noise));
        match check_case(Reader::Glb, pack(&json, &bin, delta)) {
            Ok(true) => accepted += 1,
            Ok(false) => rejected += 1,
            Err(why) => failures.push(format!("case {case} (seed {}): {why}", seeds[k].0)),
        }
    }
    eprintln!(
        "gltf fuzz: {CASES} cases over {} seeds in {:.1} s: {accepted} accepted, {rejected} rejected with a place, {} failures",
        seeds.len(),
        started.elapsed().as_secs_f64(),
        failures.len()
    );
    assert!(failures.is_empty(), "{} failing cases:\n{}", failures.len(), failures.join("\n"));
}
