//! The fit's least squares: the camera placed for each mode of the prior, then
//! Levenberg–Marquardt over the camera and the body pose from the best few.

use glam::{DMat3, DVec3, Mat4, Quat, Vec2, Vec3};
use marionette_formats::stage::CameraDoc;
use marionette_rig::body_poses::{aim_end, aim_start};
use marionette_rig::fk::forward_kinematics;
use marionette_rig::ik::rotation_of;

use marionette_rig::humanoid::HumanBone::{self, LeftLowerLeg, LeftUpperLeg, RightLowerLeg, RightUpperLeg};

use super::{Body, BodyState, Mode, Seen};
use crate::annotate::camera::Pinhole;

/// The modes refined by the full fit (the best by their camera's fit alone).
const REFINED: usize = 5;
/// The most Levenberg–Marquardt steps of one refinement.
const STEPS: usize = 40;
/// The pull toward a mode of the prior, and toward the frame before in a sequence.
const MODE_PULL: f32 = 0.03;
const FOLLOW_PULL: f32 = 0.2;
/// The field of view a camera starts from where none is given, degrees.
const START_FOV: f32 = 45.0;

/// The camera as the fit moves it: no roll (as the scene's camera has none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Camera {
    yaw: f32,
    pitch: f32,
    pub(super) eye: Vec3,
    pub(super) fov: f32,
}

impl Camera {
    /// The scene camera's turn (its yaw, then its pitch).
    fn rotation(&self) -> Quat {
        CameraDoc { yaw: self.yaw, pitch: self.pitch, ..CameraDoc::default() }.rotation()
    }

    /// Camera to world (the renderer's: it looks along its -z).
    pub(super) fn to_world(self) -> Mat4 {
        Mat4::from_rotation_translation(self.rotation(), self.eye)
    }

    /// The scene's camera, its focus `distance` ahead.
    pub(super) fn doc(&self, distance: f32) -> CameraDoc {
        let focus = self.eye - self.rotation() * Vec3::new(0.0, 0.0, distance);
        CameraDoc { focus, yaw: self.yaw, pitch: self.pitch, distance, fov: self.fov, ortho: None }
    }
}

#[derive(Debug, Clone, Copy)]
pub(super) struct State {
    pub(super) camera: Camera,
    pub(super) body: BodyState,
}

impl State {
    /// The weighted mean of states about `centre` (one of them, whose look is kept where
    /// others have none): the camera's numbers, and each direction's (made unit).
    pub(super) fn mean(centre: &State, states: &[(f32, &State)]) -> State {
        let total: f32 = states.iter().map(|(w, _)| w).sum();
        let mut out = *centre;
        let sum = |f: &dyn Fn(&State) -> f32| states.iter().map(|(w, s)| w * f(s)).sum::<f32>() / total;
        // Yaw about the centre's, so a turn through ±π averages right.
        let wrap = |a: f32| (a + std::f32::consts::PI).rem_euclid(std::f32::consts::TAU) - std::f32::consts::PI;
        out.camera.yaw = centre.camera.yaw + sum(&|s| wrap(s.camera.yaw - centre.camera.yaw));
        out.camera.pitch = sum(&|s| s.camera.pitch);
        out.camera.fov = sum(&|s| s.camera.fov);
        out.camera.eye = states.iter().map(|(w, s)| s.camera.eye * *w).sum::<Vec3>() / total;
        for k in 0..out.body.directions.len() {
            let d: Vec3 = states.iter().map(|(w, s)| s.body.directions[k] * *w).sum();
            out.body.directions[k] = d.normalize_or(centre.body.directions[k]);
        }
        if let Some(look) = centre.body.look {
            let d: Vec3 = states.iter().filter_map(|(w, s)| s.body.look.map(|l| l * *w)).sum();
            out.body.look = Some(d.normalize_or(look));
        }
        out
    }
}

/// The fit that won.
pub(super) struct Best {
    pub(super) state: State,
    pub(super) error: f32,
    pub(super) mode: String,
    cost: f64,
    /// Where the body's hips are (the camera's focus is put there).
    hips: Vec3,
}

impl Best {
    pub(super) fn camera(&self) -> CameraDoc {
        let c = self.state.camera;
        let ahead = (self.hips - c.eye).dot(c.rotation() * Vec3::NEG_Z).max(0.1);
        c.doc(ahead)
    }
}

/// A knee: its thigh's joint, its own, the ankle, and the axis (in the thigh's frame) it
/// bends about, forward of which it bends backwards.
struct Hinge {
    upper: usize,
    lower: usize,
    end: usize,
    axis: Vec3,
}

pub(super) struct Problem<'a> {
    body: &'a Body<'a>,
    seen: &'a [Seen],
    size: (u32, u32),
    fov: Option<f32>,
    /// The person's size in the picture (pixels): the prior's weights scale with it.
    scale: f32,
    hinges: Vec<Hinge>,
    /// The camera's pitch where it is held (a sequence's frames after the first).
    pitch: Option<f32>,
    /// How hard the body is pulled toward its mode, per unit of each direction's change
    /// and pixel of the person's size.
    pull: f32,
}

/// The camera's parameters in the step vector (yaw, pitch, eye), then the field of view
/// where it is estimated.
const CAMERA: usize = 5;

impl<'a> Problem<'a> {
    pub(super) fn new(body: &'a Body<'a>, seen: &'a [Seen], size: (u32, u32), fov: Option<f32>) -> Self {
        let (lo, hi) = seen.iter().fold((Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY)), |(lo, hi), s| {
            (lo.min(s.at), hi.max(s.at))
        });
        let scale = (hi - lo).length().max(10.0);
        Self { body, seen, size, fov, scale, hinges: hinges(body), pitch: None, pull: MODE_PULL }
    }

    /// The best fit from the modes.
    pub(super) fn best(&self, modes: &[Mode]) -> Best {
        let mut started: Vec<(f64, State, &Mode, Vec<f32>)> = modes
            .iter()
            .map(|mode| {
                let (points, bends) = self.posed_points(&mode.body);
                // A knee may bend backwards no further than its mode does.
                let floors: Vec<f32> = bends.iter().map(|b| b.min(0.0) - 0.05).collect();
                let camera = self.placed_camera(&points);
                let state = State { camera, body: mode.body };
                let (state, cost) = self.refine(state, mode, &floors, false);
                (cost, state, mode, floors)
            })
            .collect();
        started.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut best: Option<Best> = None;
        for (_, state, mode, floors) in started.into_iter().take(REFINED) {
            let (state, cost) = self.refine(state, mode, &floors, true);
            if best.as_ref().is_none_or(|b| cost < b.cost) {
                best = Some(self.best_of(state, cost, mode));
            }
        }
        best.expect("at least one mode")
    }

    /// A sequence's later frame: the camera's pitch held at the first frame's `state`, the
    /// body pulled harder toward the frame before.
    pub(super) fn follow(&mut self, first: &State) {
        self.pitch = Some(first.camera.pitch);
        self.pull = FOLLOW_PULL;
    }

    /// The fit warm-started from `previous` (a frame before), pulled toward its body.
    pub(super) fn from(&self, previous: &State) -> Best {
        let mode = Mode { name: "the frame before".into(), body: previous.body };
        let (_, bends) = self.posed_points(&previous.body);
        let floors: Vec<f32> = bends.iter().map(|b| b.min(0.0) - 0.05).collect();
        let (state, cost) = self.refine(*previous, &mode, &floors, true);
        self.best_of(state, cost, &mode)
    }

    /// The mean pixel error of a state.
    pub(super) fn error_of(&self, state: &State) -> f32 {
        let (points, _) = self.posed_points(&state.body);
        self.mean_error(&state.camera, &points)
    }

    fn best_of(&self, state: State, cost: f64, mode: &Mode) -> Best {
        let hips = self.hips(&state.body);
        Best { state, error: self.error_of(&state), mode: mode.name.clone(), cost, hips }
    }

    /// Where the hips joint is at this pose.
    fn hips(&self, body: &BodyState) -> Vec3 {
        let pose = self.body.posed(body);
        let mut world = vec![Mat4::IDENTITY; self.body.skeleton.len()];
        forward_kinematics(self.body.skeleton, &pose, self.body.placement, &mut world);
        let hips = self.body.map.get(&HumanBone::Hips).copied().unwrap_or(0);
        world[hips].w_axis.truncate()
    }

    /// The keypoints of a body pose and its knees' bends (negative: backwards).
    fn posed_points(&self, body: &BodyState) -> (Vec<Vec3>, Vec<f32>) {
        let pose = self.body.posed(body);
        let mut world = vec![Mat4::IDENTITY; self.body.skeleton.len()];
        let points = self.body.points(&pose, &mut world);
        let bends = self
            .hinges
            .iter()
            .map(|h| {
                let at = |j: usize| world[j].w_axis.truncate();
                let upper = (at(h.lower) - at(h.upper)).normalize_or_zero();
                let lower = (at(h.end) - at(h.lower)).normalize_or_zero();
                upper.cross(lower).dot(rotation_of(world[h.upper]) * h.axis)
            })
            .collect();
        (points, bends)
    }

    fn pinhole(&self, camera: &Camera) -> Pinhole {
        Pinhole::of(&camera.doc(1.0), self.size.0, self.size.1).expect("a perspective camera")
    }

    /// Where the camera sees a point, in pixels (a point behind it pushed just ahead).
    fn pixel(pinhole: &Pinhole, p: Vec3) -> Vec2 {
        let c = pinhole.to_camera(p);
        let (x, y) = pinhole.pixel_of(Vec3::new(c.x, c.y, c.z.max(1e-2)));
        Vec2::new(x, y)
    }

    fn mean_error(&self, camera: &Camera, points: &[Vec3]) -> f32 {
        let pinhole = self.pinhole(camera);
        let sum: f32 = self.seen.iter().map(|s| Self::pixel(&pinhole, points[s.anchor]).distance(s.at)).sum();
        sum / self.seen.len() as f32
    }

    /// The residuals: the weighted pixel misses, then (with `body`) the pull toward the
    /// mode, the knees' backward bends past their `floors` and the field of view's pull
    /// toward its start.
    fn residuals(
        &self,
        camera: &Camera,
        body: &BodyState,
        (mode, floors): (&Mode, &[f32]),
        posed: &(Vec<Vec3>, Vec<f32>),
        out: &mut Vec<f64>,
    ) {
        out.clear();
        let pinhole = self.pinhole(camera);
        for s in self.seen {
            let miss = (Self::pixel(&pinhole, posed.0[s.anchor]) - s.at) * s.weight;
            out.extend([miss.x as f64, miss.y as f64]);
        }
        let pull = self.pull * self.scale;
        for (d, m) in body.directions.iter().zip(&mode.body.directions) {
            let off = (*d - *m) * pull;
            out.extend([off.x as f64, off.y as f64, off.z as f64]);
        }
        if let (Some(l), Some(m)) = (body.look, mode.body.look) {
            let off = (l - m) * pull;
            out.extend([off.x as f64, off.y as f64, off.z as f64]);
        }
        for (&bend, &floor) in posed.1.iter().zip(floors) {
            out.push((self.scale * (bend - floor).min(0.0)) as f64);
        }
        if self.fov.is_none() {
            out.push((0.1 * self.scale * (camera.fov / START_FOV).ln()) as f64);
        }
    }

    fn cost(r: &[f64]) -> f64 {
        r.iter().map(|x| x * x).sum()
    }

    /// Levenberg–Marquardt from `state`: the camera alone, or (`whole`) the camera and body.
    fn refine(&self, mut state: State, mode: &Mode, floors: &[f32], whole: bool) -> (State, f64) {
        let mode = (mode, floors);
        let fov_free = usize::from(self.fov.is_none());
        let look = usize::from(state.body.look.is_some());
        let n = CAMERA + fov_free + if whole { 2 * 11 + 2 * look } else { 0 };
        let mut posed = self.posed_points(&state.body);
        let mut r = Vec::new();
        self.residuals(&state.camera, &state.body, mode, &posed, &mut r);
        let mut cost = Self::cost(&r);
        let mut damping = 1e-3;
        let mut column = Vec::new();
        for _ in 0..STEPS {
            // The Jacobian by forward differences, a column a parameter.
            let mut jacobian: Vec<Vec<f64>> = Vec::with_capacity(n);
            for k in 0..n {
                let h = 1e-3;
                let mut one = vec![0.0; n];
                one[k] = h;
                let moved = self.moved(&state, &one, fov_free);
                let moved_posed;
                let posed_k = if k < CAMERA + fov_free {
                    &posed
                } else {
                    moved_posed = self.posed_points(&moved.body);
                    &moved_posed
                };
                self.residuals(&moved.camera, &moved.body, mode, posed_k, &mut column);
                jacobian.push(column.iter().zip(&r).map(|(a, b)| (a - b) / h as f64).collect());
            }
            let jtj = faer::Mat::<f64>::from_fn(n, n, |i, j| dot(&jacobian[i], &jacobian[j]));
            let jtr: Vec<f64> = (0..n).map(|i| dot(&jacobian[i], &r)).collect();
            let mut improved = false;
            for _ in 0..8 {
                let Some(step) = solve_damped(&jtj, &jtr, damping) else {
                    damping *= 10.0;
                    continue;
                };
                let step: Vec<f32> = step.iter().map(|&d| d as f32).collect();
                let trial = self.moved(&state, &step, fov_free);
                let trial_posed = if whole { self.posed_points(&trial.body) } else { posed.clone() };
                self.residuals(&trial.camera, &trial.body, mode, &trial_posed, &mut column);
                let trial_cost = Self::cost(&column);
                if trial_cost < cost {
                    let gain = (cost - trial_cost) / cost.max(1e-12);
                    (state, posed, cost) = (trial, trial_posed, trial_cost);
                    std::mem::swap(&mut r, &mut column);
                    damping = (damping / 3.0).max(1e-9);
                    improved = gain > 1e-7;
                    break;
                }
                damping *= 8.0;
            }
            if !improved {
                break;
            }
        }
        (state, cost)
    }

    /// `state` moved by `step`: yaw, pitch, the eye's x, y, z, the field of view (its
    /// logarithm, where estimated), then two a bone direction and the look, each a turn
    /// about the two axes square to it.
    fn moved(&self, state: &State, step: &[f32], fov_free: usize) -> State {
        let mut s = *state;
        s.camera.yaw += step[0];
        s.camera.pitch = self.pitch.unwrap_or((s.camera.pitch + step[1]).clamp(-1.55, 1.55));
        s.camera.eye += Vec3::new(step[2], step[3], step[4]);
        if fov_free == 1 {
            s.camera.fov = (s.camera.fov * step[CAMERA].exp()).clamp(5.0, 150.0);
        }
        let turn = |v: Vec3, a: f32, b: f32| {
            let (u, w) = v.any_orthonormal_pair();
            (Quat::from_scaled_axis(u * a + w * b) * v).normalize()
        };
        let body = &step[CAMERA + fov_free..];
        for (bone, pair) in body.chunks_exact(2).enumerate() {
            match bone {
                0..=10 => s.body.directions[bone] = turn(s.body.directions[bone], pair[0], pair[1]),
                _ => s.body.look = s.body.look.map(|l| turn(l, pair[0], pair[1])),
            }
        }
        s
    }

    /// A camera for these keypoints: for each of a ring of yaws and a few pitches, the eye
    /// that best puts the points on the file's (a linear least squares), the best kept.
    fn placed_camera(&self, points: &[Vec3]) -> Camera {
        let fov = self.fov.unwrap_or(START_FOV);
        let mut best: Option<(f32, Camera)> = None;
        for step in 0..12 {
            for pitch in [-0.4, -0.15, 0.1] {
                let yaw = step as f32 * std::f32::consts::TAU / 12.0;
                let Some(eye) = self.eye_for(yaw, pitch, fov, points) else { continue };
                let camera = Camera { yaw, pitch, eye, fov };
                let pinhole = self.pinhole(&camera);
                if self.seen.iter().any(|s| pinhole.to_camera(points[s.anchor]).z <= 0.05) {
                    continue;
                }
                let error = self.mean_error(&camera, points);
                if best.is_none_or(|(e, _)| error < e) {
                    best = Some((error, camera));
                }
            }
        }
        best.map_or(Camera { yaw: 0.0, pitch: 0.0, eye: points[0] + Vec3::new(0.0, 0.0, 5.0), fov }, |(_, c)| c)
    }

    /// The eye that puts `points` nearest the file's for a camera turned by yaw and pitch:
    /// each point's projection equations are linear in the camera-frame translation.
    fn eye_for(&self, yaw: f32, pitch: f32, fov: f32, points: &[Vec3]) -> Option<Vec3> {
        // World to the camera's frame (OpenCV's axes) of the camera at the origin: its turn.
        let pinhole = self.pinhole(&Camera { yaw, pitch, eye: Vec3::ZERO, fov });
        let q = glam::Mat3::from_mat4(pinhole.world_to_camera);
        let [[f, _, cx], [_, _, cy], _] = pinhole.k().map(|row| row.map(f64::from));
        let (mut a, mut b) = (DMat3::ZERO, DVec3::ZERO);
        for s in self.seen {
            let p = (q * points[s.anchor]).as_dvec3();
            let w = (s.weight as f64).powi(2);
            for (row, rhs) in [
                (DVec3::new(f, 0.0, -(s.at.x as f64 - cx)), (s.at.x as f64 - cx) * p.z - f * p.x),
                (DVec3::new(0.0, f, -(s.at.y as f64 - cy)), (s.at.y as f64 - cy) * p.z - f * p.y),
            ] {
                a += DMat3::from_cols(row * row.x, row * row.y, row * row.z) * w;
                b += row * rhs * w;
            }
        }
        if a.determinant().abs() < 1e-12 {
            return None;
        }
        let t = (a.inverse() * b).as_vec3();
        Some(-(q.transpose() * t))
    }
}

/// The knees, each with the axis its thigh bends the shin about at rest (the facing
/// frame's left: a knee bends backwards).
fn hinges(body: &Body) -> Vec<Hinge> {
    let skeleton = body.skeleton;
    let mut rest = vec![Mat4::IDENTITY; skeleton.len()];
    forward_kinematics(skeleton, &skeleton.initial_pose(), body.placement, &mut rest);
    let left = body.placement.transform_vector3(body.frame * Vec3::X).normalize();
    [(LeftUpperLeg, LeftLowerLeg), (RightUpperLeg, RightLowerLeg)]
        .into_iter()
        .filter_map(|(thigh, shin)| {
            let upper = aim_start(body.map, thigh)?;
            let lower = aim_end(body.map, thigh)?;
            let end = aim_end(body.map, shin)?;
            let axis = rotation_of(rest[upper]).inverse() * left;
            Some(Hinge { upper, lower, end, axis })
        })
        .collect()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The Levenberg–Marquardt step: `(JᵀJ + λ diag(JᵀJ)) δ = −Jᵀr`.
fn solve_damped(jtj: &faer::Mat<f64>, jtr: &[f64], damping: f64) -> Option<Vec<f64>> {
    let n = jtr.len();
    let a =
        faer::Mat::<f64>::from_fn(n, n, |i, j| if i == j { jtj[(i, i)] * (1.0 + damping) + 1e-9 } else { jtj[(i, j)] });
    let llt = a.llt(faer::Side::Lower).ok()?;
    let rhs = faer::Mat::<f64>::from_fn(n, 1, |i, _| -jtr[i]);
    use faer::linalg::solvers::Solve;
    let x = llt.solve(&rhs);
    let step: Vec<f64> = (0..n).map(|i| x[(i, 0)]).collect();
    step.iter().all(|v| v.is_finite()).then_some(step)
}
