//! The COCO keypoints file of a picture (or of a sequence, an image per frame): COCO's own
//! fields, which pycocotools reads, and beside them the camera, each annotation's character,
//! instance id and its humanoid bones in world metres.

use serde_json::{Value, json};

use super::{Figure, JOINT_TOLERANCE, PARTS, Passes, Pinhole, SURFACE_TOLERANCE, seen};
use crate::annotate::camera::{FAR, NEAR};
use crate::annotate::raster::FLOOR;

/// COCO's 17 keypoints, in its order.
pub const KEYPOINTS: [&str; 17] = [
    "nose",
    "left_eye",
    "right_eye",
    "left_ear",
    "right_ear",
    "left_shoulder",
    "right_shoulder",
    "left_elbow",
    "right_elbow",
    "left_wrist",
    "right_wrist",
    "left_hip",
    "right_hip",
    "left_knee",
    "right_knee",
    "left_ankle",
    "right_ankle",
];

/// COCO's skeleton: pairs of keypoints, numbered from 1.
pub const SKELETON: [[u8; 2]; 19] = [
    [16, 14],
    [14, 12],
    [17, 15],
    [15, 13],
    [12, 13],
    [6, 12],
    [7, 13],
    [6, 7],
    [6, 8],
    [7, 9],
    [8, 10],
    [9, 11],
    [2, 3],
    [1, 2],
    [1, 3],
    [2, 4],
    [3, 5],
    [4, 6],
    [5, 7],
];

/// The category of people (with keypoints) and of props.
const PERSON: u32 = 1;
const OBJECT: u32 = 2;

/// The camera as the files give it: `K` (rows), `world_to_camera` (4×4, rows; OpenCV's
/// frame), the picture's size and the depth range.
pub fn camera_json(camera: &Pinhole) -> Value {
    let m = camera.world_to_camera.transpose().to_cols_array_2d();
    json!({
        "K": camera.k(),
        "world_to_camera": m,
        "width": camera.width,
        "height": camera.height,
        "near": NEAR,
        "far": FAR,
        "convention": "OpenCV: x right, y down, z forward (depth); pixel (0, 0) covers [0, 1) x [0, 1); world metres, y up",
    })
}

/// A picture's entry in `images`.
pub fn image_json(id: u64, file_name: &str, camera: &Pinhole) -> Value {
    json!({ "id": id, "file_name": file_name, "width": camera.width, "height": camera.height, "camera": camera_json(camera) })
}

/// The annotations of each figure seen in the picture (ids from `first_id`).
pub fn annotations(camera: &Pinhole, passes: &Passes, figures: &[Figure], image_id: u64, first_id: u64) -> Vec<Value> {
    let mut out = Vec::new();
    for figure in figures {
        let mine = |i: usize| passes.instance[i] == figure.instance;
        let Some(bbox) = mask_box(passes, figure.instance) else { continue };
        let area = (0..passes.instance.len()).filter(|&i| mine(i)).count();
        let mut keypoints = Vec::with_capacity(3 * KEYPOINTS.len());
        let mut count = 0;
        for name in KEYPOINTS {
            let (x, y, v) = figure.points.get(name).map_or((0.0, 0.0, 0), |p| seen(camera, passes, figure.instance, p));
            count += usize::from(v > 0);
            keypoints.extend([json!(x), json!(y), json!(v)]);
        }
        let joints_3d: serde_json::Map<String, Value> =
            figure.bones.iter().map(|(bone, p)| (format!("{bone:?}"), json!([p.x, p.y, p.z]))).collect();
        out.push(json!({
            "id": first_id + out.len() as u64,
            "image_id": image_id,
            "category_id": if figure.is_person() { PERSON } else { OBJECT },
            "iscrowd": 0,
            "bbox": bbox,
            "area": area,
            "segmentation": rle(passes, figure.instance),
            "keypoints": keypoints,
            "num_keypoints": count,
            "character": figure.name,
            "instance_id": figure.instance,
            "joints_3d": joints_3d,
        }));
    }
    out
}

/// The whole file: images, annotations, the categories, the camera of the first picture,
/// and the tables the masks and visibilities use.
pub fn file(images: Vec<Value>, annotations: Vec<Value>) -> Value {
    let camera = images.first().map_or(Value::Null, |i| i["camera"].clone());
    json!({
        "info": { "description": "Marionette data picture", "version": env!("CARGO_PKG_VERSION") },
        "images": images,
        "annotations": annotations,
        "categories": [
            { "id": PERSON, "name": "person", "supercategory": "person", "keypoints": KEYPOINTS, "skeleton": SKELETON },
            { "id": OBJECT, "name": "object", "supercategory": "object", "keypoints": [], "skeleton": [] },
        ],
        "camera": camera,
        "parts": PARTS,
        "visibility": {
            "surface_tolerance_m": SURFACE_TOLERANCE,
            "joint_tolerance_m": JOINT_TOLERANCE,
            "rule": "v = 2 where no surface lies in front of the point by more than surface_tolerance_m, or (for a joint) \
                     where its pixel shows its own limb within joint_tolerance_m in front of it; v = 1 otherwise inside the \
                     picture; v = 0 outside it, behind the camera, or where the rig has no such point",
        },
    })
}

/// The instance's pixels' box `[x, y, width, height]`; none where it has none.
pub fn mask_box(passes: &Passes, instance: u16) -> Option<[u32; 4]> {
    let (mut lo, mut hi) = ((u32::MAX, u32::MAX), (0, 0));
    for y in 0..passes.height {
        for x in 0..passes.width {
            if passes.instance[passes.at(x, y)] == instance {
                lo = (lo.0.min(x), lo.1.min(y));
                hi = (hi.0.max(x), hi.1.max(y));
            }
        }
    }
    (lo.0 != u32::MAX).then(|| [lo.0, lo.1, hi.0 - lo.0 + 1, hi.1 - lo.1 + 1])
}

/// COCO's uncompressed run-length encoding of the instance's mask: runs down the columns,
/// left to right, starting with a run of pixels outside it.
pub fn rle(passes: &Passes, instance: u16) -> Value {
    let mut counts = Vec::new();
    let (mut inside, mut run) = (false, 0u32);
    for x in 0..passes.width {
        for y in 0..passes.height {
            let here = passes.instance[passes.at(x, y)] == instance && instance != FLOOR;
            if here != inside {
                counts.push(run);
                (inside, run) = (here, 0);
            }
            run += 1;
        }
    }
    counts.push(run);
    json!({ "counts": counts, "size": [passes.height, passes.width] })
}
