//! A bounded mutation fuzzer over every reader: the real course files (when
//! `MARIONETTE_DATA` is set), the project's assets and small inline seeds are mutated (byte
//! flips, deleted, duplicated or swapped spans, numbers replaced by extremes, truncation)
//! with decisions drawn through `arbitrary` from a seeded generator, so every run replays
//! the same cases. Each case must return (no panic, no hang), stay within a memory bound,
//! and a rejection must say where: `file:line: …`, or a JSON / scene field path.
//!
//! A case that fails is printed with its seed; the input becomes a file under
//! `tests/regressions/` (see `regressions_are_rejected_with_a_place`).

use std::io::Cursor;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use arbitrary::Unstructured;
use marionette::formats::{FormatError, bvh, cse169, cse169_skin, homer, mit6837, obj, off, scene, smpl};

use crate::common::data_dir;

/// Cases per run (a few seconds on two cores in the test profile).
const CASES: usize = 20_000;
/// Seeds are cut to this many bytes (at a line end) so a case stays fast.
const SEED_BYTES: usize = 24 * 1024;
/// A case taking longer than this counts as a hang.
const CASE_TIME_LIMIT: Duration = Duration::from_secs(5);
/// Peak heap growth allowed for one case, beyond a multiple of its input.
const MEMORY_BASE: usize = 64 << 20;
const MEMORY_PER_INPUT_BYTE: usize = 256;

/// Which reader a seed goes to, with what it needs besides the bytes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Reader {
    Skel6837,
    Attach {
        joints: usize,
        vertices: usize,
    },
    Cse169Skel,
    Cse169Skin,
    /// A morph for a skin of this many vertices.
    Cse169Morph {
        vertices: usize,
    },
    Cse169Anim,
    Bvh,
    Glb,
    Fbx,
    Obj,
    Off,
    SmplHierarchy,
    SmplSkeleton,
    SmplSkin,
    SmplClip,
    HomerRig,
    /// A rig JSON with a small fixed mesh: parsing, then weights or smooth binding.
    HomerCharacter,
    Scene,
}

/// Runs one reader on `bytes`: `Ok(())` when it accepted, the error when it rejected.
fn read(reader: Reader, bytes: &[u8]) -> Result<(), FormatError> {
    let path = Path::new("case");
    let input = Cursor::new(bytes);
    match reader {
        Reader::Skel6837 => mit6837::parse_skel(input, path).map(drop),
        Reader::Attach { joints, vertices } => mit6837::parse_attach(input, path, joints, vertices).map(drop),
        Reader::Cse169Skel => cse169::parse_skel(input, path).map(drop),
        Reader::Cse169Skin => cse169_skin::parse_skin(input, path).map(drop),
        Reader::Cse169Morph { vertices } => cse169_skin::parse_morph(input, path, vertices).map(drop),
        Reader::Cse169Anim => cse169_skin::parse_anim(input, path).map(drop),
        Reader::Bvh => bvh::parse_bvh(input, path).map(drop),
        Reader::Glb => marionette::formats::gltf_import::parse_gltf(bytes, path).map(|characters| {
            // Sampling whatever clips were read must not panic either.
            for c in &characters {
                for clip in &c.clips {
                    for t in [-1.0, 0.0, 0.3, 1e9, f32::NAN] {
                        clip.sample(&c.asset.skeleton, t);
                    }
                }
            }
        }),
        Reader::Fbx => marionette::formats::fbx::parse_fbx(bytes, path).map(|parts| {
            for c in &parts {
                for clip in &c.clips {
                    for t in [-1.0, 0.0, 0.3, 1e9, f32::NAN] {
                        clip.sample(&c.asset.skeleton, t);
                    }
                }
            }
        }),
        Reader::Obj => obj::parse_obj(input, path).map(drop),
        Reader::Off => off::parse_off(input, path).map(drop),
        Reader::SmplHierarchy => smpl::parse_hierarchy(input, path).map(drop),
        Reader::SmplSkeleton => smpl::parse_skeleton_positions(input, path, 24).map(drop),
        Reader::SmplSkin => smpl::parse_skin(input, path, 24).map(drop),
        Reader::SmplClip => smpl::parse_clip(input, path, 24).map(drop),
        Reader::HomerRig => homer::parse_rig(input, path).map(drop),
        Reader::HomerCharacter => {
            let mesh = off::parse_off(Cursor::new(SMALL_OFF), Path::new("small.off")).expect("a valid mesh");
            homer::homer_character("h".into(), homer::parse_rig(input, path)?, mesh, path).map(drop)
        }
        Reader::Scene => scene::parse_scene(input, path).map(drop),
    }
}

/// The mesh given to `HomerCharacter` cases (vertices 0..=3).
const SMALL_OFF: &str = "OFF\n4 2 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n4 0 1 3 2 255 0 0\n";

/// Whether an error says where in the file the problem is.
fn names_a_place(e: &FormatError) -> bool {
    match e {
        FormatError::Syntax { line, .. } => *line >= 1,
        FormatError::Other { message, .. } => {
            // An FBX file's place is its element (a node, mesh, cluster or stack, named), or
            // where ufbx stopped reading it (its own description).
            let fbx = ["node `", "mesh `", "skin cluster `", "animation stack `", "the node tree", "the skin weights"];
            ["at $", "at byte ", "characters[", "camera.", "stage.", "poses[", "shot.", "bookmarks["]
                .iter()
                .chain(&fbx)
                .chain(&["expected an FBX file, ", "expected a node with a mesh"])
                .any(|p| message.starts_with(p))
        }
        FormatError::Rig { .. } | FormatError::Io { .. } => false,
    }
}

/// A file, or for a large one its first and last `SEED_BYTES / 2` cut at line ends (so
/// headers and later sections such as faces are both mutated; a cut file is invalid, which
/// is fine for mutation), and whether it is whole.
fn seed_prefix(bytes: Vec<u8>) -> (Vec<u8>, bool) {
    if bytes.len() <= SEED_BYTES {
        return (bytes, true);
    }
    let half = SEED_BYTES / 2;
    let head = bytes[..half].iter().rposition(|&b| b == b'\n').map_or(half, |i| i + 1);
    let from = bytes.len() - half;
    let tail = bytes[from..].iter().position(|&b| b == b'\n').map_or(from, |i| from + i + 1);
    ([&bytes[..head], &bytes[tail..]].concat(), false)
}

fn lines(bytes: &[u8]) -> usize {
    String::from_utf8_lossy(bytes).lines().filter(|l| !l.trim().is_empty()).count()
}

/// Small seeds that need no files, one or more per reader.
fn inline_seeds() -> Vec<Seed> {
    let s = |reader, t: &str| Seed { reader, bytes: t.as_bytes().to_vec(), whole: true };
    vec![
        s(Reader::Skel6837, "0 0 0 -1\n0 1 0 0\n0 1 0 1\n1 0 0 0\n"),
        s(Reader::Attach { joints: 4, vertices: 3 }, "1 0 0\n0.5 0.5 0\n0 0 1\n"),
        s(
            Reader::Cse169Skel,
            "balljoint root {\n offset 0 0 0\n boxmin -1 -1 -1 boxmax 1 1 1\n rotxlimit -1 1\n pose 0 0.5 0\n balljoint a{ offset 0 1 0 balljoint b { offset 0 1 0 } }\n}\n",
        ),
        s(
            Reader::Cse169Skin,
            "positions 3 {0 0 0 1 0 0 0 1 0}\nnormals 3 {0 0 1 0 0 1 0 0 1}\ntexcoords 3 {0 0 1 0 0 1}\nskinweights 3 {1 0 1 2 0 0.5 1 0.5 1 1 1}\nmaterial m {texture t.bmp}\ntriangles 1 {0 1 2}\nbindings 2 {matrix {1 0 0 0 1 0 0 0 1 0 0 0} matrix {1 0 0 0 1 0 0 0 1 0 1 0}}\n",
        ),
        s(Reader::Cse169Morph { vertices: 4 }, "positions 2 {\n0 0 0 1\n3 1 1 1\n}\nnormals 1 {\n0 0 0 1\n}\n"),
        s(
            Reader::Cse169Anim,
            "animation {\n range 0 2\n numchannels 2\n channel {\n extrapolate cycle_offset bounce\n keys 3 {\n 0 0 smooth smooth\n 1 1 linear flat\n 2 0 0.5 -1\n }\n }\n channel 1{\n extrapolate linear constant\n keys 1 {\n 0 1 flat flat\n }\n }\n}\n",
        ),
        s(Reader::Obj, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2/1 4/2 3/3\nf -1 -2 -3\n"),
        s(Reader::Off, SMALL_OFF),
        s(Reader::SmplHierarchy, &smpl_hierarchy()),
        s(Reader::SmplSkeleton, &format!("1 24\n{}\n", vec!["0 0 0 1 0.1 0.2 0.3"; 24].join(" "))),
        s(Reader::SmplSkin, &format!("2 24 2\n0 0.5 1 0.5\n{}\n", "23 1 0 0")),
        s(Reader::SmplClip, &format!("2 24\n0 0 0 {}\n0 1 0 {}\n", "0 0 0 1 ".repeat(24), "0 0 0.7 0.7 ".repeat(24))),
        s(
            Reader::HomerRig,
            r#"{"root":{"pos":[0,0,0],"children":["a"]},"a":{"pos":[0,1,0],"children":["b"],"weights":{"0":0.5,"1":1}},"b":{"pos":[0,2,0]}}"#,
        ),
        s(
            Reader::HomerCharacter,
            r#"{"root":{"pos":[0,0,0],"children":["a","c"]},"a":{"pos":[0,1,0],"children":["b"]},"b":{"pos":[0,2,0]},"c":{"pos":[1,0,0]}}"#,
        ),
        s(
            Reader::HomerCharacter,
            r#"{"root":{"pos":[0,0,0],"children":["a"],"weights":{"0":1,"1":0.5,"2":1,"3":1}},"a":{"pos":[0,1,0],"weights":{"1":0.5}}}"#,
        ),
        s(
            Reader::Scene,
            r#"(characters:[(source:Embedded("puppet"),name:"p",placement:(translation:(1,0,0),yaw:0.5,scale:2),pose:{"l_elbow":Euler((0,1,0),Xyz),"x":Quat((0,0,0,1))},smpl:Some((betas:[1,2],clip:Some("c"),time:3,blend:0.5)))],camera:Some((focus:(0,1,0),yaw:0,pitch:-0.2,distance:3)),stage:(floor:true,shadows:false,axes:true,floor_height:0))"#,
        ),
    ]
}

fn smpl_hierarchy() -> String {
    let mut t = "24\n0 -1 EULER_XYZ pelvis\n".to_string();
    for k in 1..24 {
        t += &format!("{k} {} EULER_XYZ j{k}\n", (k - 1) / 2);
    }
    t
}

/// An input to mutate, for one reader.
struct Seed {
    reader: Reader,
    bytes: Vec<u8>,
    /// The whole file (not cut to `SEED_BYTES`), which the reader must accept.
    whole: bool,
}

/// Reads a seed file, cut to [`SEED_BYTES`].
fn seed(reader: Reader, p: PathBuf) -> Seed {
    let (bytes, whole) = std::fs::read(&p).map(seed_prefix).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
    Seed { reader, bytes, whole }
}

/// An attach seed: its skeleton's joint count and its own (possibly cut) line count.
fn attach(skel: PathBuf, attach: PathBuf) -> Seed {
    let joints = lines(&std::fs::read(&skel).unwrap());
    let cut = seed(Reader::Obj, attach);
    Seed { reader: Reader::Attach { joints, vertices: lines(&cut.bytes) }, ..cut }
}

/// Seeds from the project's own assets and fixtures.
fn file_seeds() -> Vec<Seed> {
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    vec![
        seed(Reader::Skel6837, assets.join("puppet.skel")),
        seed(Reader::Obj, assets.join("puppet.obj")),
        seed(Reader::Scene, assets.join("default_scene.ron")),
        seed(Reader::Bvh, Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/steps.bvh")),
        Seed {
            reader: Reader::Glb,
            bytes: std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender_arm.glb")).unwrap(),
            whole: true,
        },
        Seed {
            reader: Reader::Glb,
            bytes: std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/blender_pair.glb")).unwrap(),
            whole: true,
        },
        Seed {
            reader: Reader::Fbx,
            bytes: std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/one_key.fbx")).unwrap(),
            whole: true,
        },
        attach(assets.join("puppet.skel"), assets.join("puppet.attach")),
    ]
}

/// Seeds from the course data folder.
fn course_seeds() -> Vec<Seed> {
    let data = data_dir();
    let mut seeds = Vec::new();
    let course = data.join("mit6837");
    for m in 1..=4 {
        let skel = course.join(format!("Model{m}.skel"));
        seeds.push(attach(skel.clone(), course.join(format!("Model{m}.attach"))));
        seeds.push(seed(Reader::Skel6837, skel));
        seeds.push(seed(Reader::Obj, course.join(format!("Model{m}.obj"))));
    }
    for f in ["test.skel", "wasp.skel", "dragon.skel"] {
        seeds.push(seed(Reader::Cse169Skel, data.join("cse169/project1").join(f)));
    }
    let cse169 = data.join("cse169");
    for f in ["project2/tube.skin", "project2/wasp.skin", "legacy/triangle.skin"] {
        seeds.push(seed(Reader::Cse169Skin, cse169.join(f)));
    }
    for f in ["extras/head1.morph", "extras/head2.morph"] {
        seeds.push(seed(Reader::Cse169Morph { vertices: 3078 }, cse169.join(f)));
    }
    for f in ["project3/wasp_walk.anim", "project3/sample.anim", "legacy/wasp_walk.anim"] {
        seeds.push(seed(Reader::Cse169Anim, cse169.join(f)));
    }
    let homer = data.join("homer");
    seeds.push(seed(Reader::Off, homer.join("homer.off")));
    seeds.push(seed(Reader::HomerRig, homer.join("homerskel.json")));
    seeds.push(seed(Reader::HomerCharacter, homer.join("homerskel.json")));
    seeds.push(seed(Reader::HomerRig, homer.join("homer.json")));
    let smpl = data.join("smpl");
    seeds.push(seed(Reader::SmplHierarchy, smpl.join("smpl_hierarchy.txt")));
    seeds.push(seed(Reader::SmplSkeleton, smpl.join("smpl_skel00.txt")));
    seeds.push(seed(Reader::SmplSkin, smpl.join("smpl_skin.txt")));
    seeds.push(seed(Reader::SmplClip, smpl.join("smpl_quaternions_mosh_cmu_7516.txt")));
    seeds.push(seed(Reader::Obj, smpl.join("smpl_00.obj")));
    seeds
}

/// Numbers that break careless readers.
const EXTREMES: &[&str] = &[
    "nan",
    "NaN",
    "inf",
    "-inf",
    "1e39",
    "-1e39",
    "3e38",
    "0",
    "-0",
    "-1",
    "-2",
    "1e-45",
    "65535",
    "65536",
    "4294967296",
    "9223372036854775807",
    "9223372036854775809",
    "18446744073709551615",
    "99999999999999999999999",
    "",
    "{",
    "}",
    "balljoint",
];

/// A splitmix64 stream: the bytes `arbitrary` draws its decisions from.
pub(crate) fn random_bytes(seed: u64, n: usize) -> Vec<u8> {
    let mut state = seed;
    let mut out = Vec::with_capacity(n + 8);
    while out.len() < n {
        state = state.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = state;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        out.extend_from_slice(&(z ^ (z >> 31)).to_le_bytes());
    }
    out
}

/// The spans of number-like tokens in `bytes`.
fn number_spans(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut start = None;
    for (i, &b) in bytes.iter().enumerate() {
        let numeric = b.is_ascii_digit() || matches!(b, b'-' | b'+' | b'.' | b'e' | b'E');
        match (numeric, start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                spans.push((s, i));
                start = None;
            }
            _ => {}
        }
    }
    if let Some(s) = start {
        spans.push((s, bytes.len()));
    }
    spans
}

/// Applies one to four mutations chosen by `u`.
fn mutate(mut bytes: Vec<u8>, u: &mut Unstructured) -> arbitrary::Result<Vec<u8>> {
    for _ in 0..u.int_in_range(1..=4)? {
        let len = bytes.len();
        let at = if len == 0 { 0 } else { u.choose_index(len)? };
        let span = u.int_in_range(1..=64usize)?.min(len - at.min(len));
        match u.int_in_range(0..=8)? {
            0 if len > 0 => bytes[at] ^= 1 << u.int_in_range(0..=7)?,
            1 => {
                bytes.drain(at..at + span);
            }
            2 => {
                let copy = bytes[at..at + span].to_vec();
                let to = if bytes.is_empty() { 0 } else { u.choose_index(bytes.len())? };
                bytes.splice(to..to, copy);
            }
            3 | 7 | 8 => {
                // Numbers, half the time the first of a line (counts, parents, polygon sizes).
                let mut spans = number_spans(&bytes);
                if u.arbitrary()? {
                    spans.retain(|&(s, _)| s == 0 || bytes[s - 1] == b'\n');
                }
                if !spans.is_empty() {
                    let (s, e) = spans[u.choose_index(spans.len())?];
                    bytes.splice(s..e, u.choose(EXTREMES)?.bytes());
                }
            }
            4 => bytes.truncate(at),
            5 => {
                let b: u8 = u.arbitrary()?;
                let special = *u.choose(&[b'\n', b'\r', b' ', b'{', b'}', b'#', b'/', b'"', b'-', b'0', b'9', b])?;
                bytes.insert(at, special);
            }
            _ => {
                // Swap two lines.
                let text = String::from_utf8_lossy(&bytes).into_owned();
                let mut lines: Vec<&str> = text.split('\n').collect();
                if lines.len() > 1 {
                    let (a, b) = (u.choose_index(lines.len())?, u.choose_index(lines.len())?);
                    lines.swap(a, b);
                    bytes = lines.join("\n").into_bytes();
                }
            }
        }
    }
    Ok(bytes)
}

/// Runs one case: whether the reader accepted the input, or what it did wrong.
pub(crate) fn check_case(reader: Reader, input: Vec<u8>) -> Result<bool, String> {
    let limit = MEMORY_BASE + MEMORY_PER_INPUT_BYTE * input.len();
    let (tx, rx) = std::sync::mpsc::channel();
    let case = input.clone();
    // A thread of its own, so a hang is seen as one (and a panic is caught there).
    std::thread::Builder::new()
        .stack_size(8 << 20)
        .spawn(move || {
            crate::alloc::reset_peak();
            let result = std::panic::catch_unwind(|| read(reader, &case));
            let _ = tx.send((result.map(|r| r.err()), crate::alloc::peak()));
        })
        .expect("a thread");
    match rx.recv_timeout(CASE_TIME_LIMIT) {
        Err(_) => Err(format!("no answer within {CASE_TIME_LIMIT:?} (a hang)")),
        Ok((Err(_), _)) => Err("panicked".into()),
        Ok((Ok(_), peak)) if peak > limit => {
            Err(format!("used {peak} bytes of heap for {} bytes of input (limit {limit})", input.len()))
        }
        Ok((Ok(Some(e)), _)) if !names_a_place(&e) => Err(format!("a rejection that names no place: {e}")),
        Ok((Ok(error), _)) => Ok(error.is_none()),
    }
}

#[test]
fn mutated_inputs_never_panic_hang_or_balloon_and_rejections_name_a_line() {
    let mut seeds = inline_seeds();
    seeds.extend(file_seeds());
    fuzz_readers(&seeds);
}

/// The same from the course data's files.
#[test]
#[cfg_attr(not(marionette_data), ignore = "needs MARIONETTE_DATA (the course data)")]
fn mutated_course_files_never_panic_hang_or_balloon_and_rejections_name_a_line() {
    fuzz_readers(&course_seeds());
}

/// [`CASES`] byte mutations of `seeds`: none panics, hangs or balloons, every rejection
/// names its line.
fn fuzz_readers(seeds: &[Seed]) {
    // Every whole seed is accepted (the mutations start from valid files).
    for seed in seeds.iter().filter(|s| s.whole) {
        if let Err(e) = read(seed.reader, &seed.bytes) {
            panic!("{:?} seed rejected: {e}", seed.reader);
        }
    }
    let started = Instant::now();
    let mut failures = Vec::new();
    let (mut accepted, mut rejected) = (0, 0);
    for case in 0..CASES {
        let Seed { reader, bytes, .. } = &seeds[case % seeds.len()];
        let noise = random_bytes(case as u64, 256);
        let input = mutate(bytes.clone(), &mut Unstructured::new(&noise)).unwrap_or_else(|_| bytes.clone());
        match check_case(*reader, input.clone()) {
            Ok(true) => accepted += 1,
            Ok(false) => rejected += 1,
            Err(why) => {
                let shown = String::from_utf8_lossy(&input[..input.len().min(200)]).into_owned();
                failures.push(format!("case {case} ({reader:?}): {why}\n  input starts: {shown:?}"));
            }
        }
    }
    eprintln!(
        "fuzz: {CASES} cases over {} seeds in {:.1} s: {accepted} accepted, {rejected} rejected with a place, {} failures",
        seeds.len(),
        started.elapsed().as_secs_f64(),
        failures.len()
    );
    assert!(failures.is_empty(), "{} failing cases:\n{}", failures.len(), failures.join("\n"));
}

/// Every file under `tests/regressions/` (inputs that once crashed or fooled a reader) is
/// rejected with a place, never a panic. The reader is named by the file's extension.
#[test]
fn regressions_are_rejected_with_a_place() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/regressions");
    let mut seen = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let reader = match name.rsplit('.').next().unwrap() {
            "skel" if name.contains("cse169") => Reader::Cse169Skel,
            "skel" => Reader::Skel6837,
            "skin" => Reader::Cse169Skin,
            "anim" => Reader::Cse169Anim,
            "bvh" => Reader::Bvh,
            "off" => Reader::Off,
            "obj" => Reader::Obj,
            "json" if name.contains("character") => Reader::HomerCharacter,
            "json" => Reader::HomerRig,
            "ron" => Reader::Scene,
            "glb" | "gltf" => Reader::Glb,
            "fbx" => Reader::Fbx,
            "txt" if name.contains("skin") => Reader::SmplSkin,
            "txt" if name.contains("clip") => Reader::SmplClip,
            "txt" if name.contains("hierarchy") => Reader::SmplHierarchy,
            "txt" if name.contains("skeleton") => Reader::SmplSkeleton,
            _ => continue,
        };
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(check_case(reader, bytes), Ok(false), "{name}: expected a rejection that names a place");
        seen += 1;
    }
    assert!(seen >= 8, "only {seen} regression files");
}
