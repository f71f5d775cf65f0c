//! How a render draws the scenes of a data set: in what order, which of them one frame draws
//! together, and which are drawn right in their first frame. The pictures do not depend on
//! any of it; the frames they take do.

use marionette_formats::scene::{DisplayDoc, MotionSourceDoc, SceneDoc, StageDoc};

/// The most scenes a frame draws.
pub const MAX_SCENES_A_FRAME: usize = 4;

/// The pixels a frame draws at most when it draws several scenes.
const PIXELS_A_FRAME: u32 = 1280 * 960;

/// How many scenes a frame draws for pictures drawn at `width` × `height`: on a GPU as many
/// as fill [`PIXELS_A_FRAME`], from one to [`MAX_SCENES_A_FRAME`]; one on a rasteriser that
/// runs `on_cpu` (llvmpipe), whose frames cost their pixels whatever else they draw.
pub fn scenes_a_frame(width: u32, height: u32, on_cpu: bool) -> usize {
    match on_cpu {
        true => 1,
        false => (PIXELS_A_FRAME / width.saturating_mul(height).max(1)).clamp(1, MAX_SCENES_A_FRAME as u32) as usize,
    }
}

/// Whether a scene may be drawn beside others in one frame: its characters drawn as plain
/// skins (the editor's drawings are on the first scene's layer), none held by or moving
/// with another (characters are found by ids, which the scenes of a frame share), no lamp
/// casting shadows (Bevy details every lamp's shadow map for one camera of the world).
pub fn shares_a_frame(doc: &SceneDoc) -> bool {
    let found_by_id = |c: &marionette_formats::scene::CharacterDoc| {
        let moved_by_another = c.anim.as_ref().and_then(|a| a.retarget.as_ref());
        c.attached.is_some() || moved_by_another.is_some_and(|r| matches!(r.from, MotionSourceDoc::Character(_)))
    };
    plainly_drawn(doc) && !doc.characters.iter().any(found_by_id) && !doc.stage.lamps.iter().any(|l| l.shadows)
}

/// How many of the pictures `next` (their scenes from the next picture on; `None` for a
/// picture that is not a scene of its own) one frame of `slots` scenes draws: those from
/// the first on whose scenes share a frame, or the first alone.
pub fn drawn_together<'a>(next: impl IntoIterator<Item = Option<&'a SceneDoc>>, slots: usize) -> usize {
    next.into_iter().take(slots).take_while(|doc| doc.is_some_and(shares_a_frame)).count().max(1)
}

/// Whether every character of `doc` is drawn as a plain skin: no skeleton drawn, no weight
/// colours, no heat map, solid (what a data set's scenes are, and what the renderer takes up
/// in a scene's first frame: the other views add drawings and materials of later frames).
pub fn plainly_drawn(doc: &SceneDoc) -> bool {
    doc.characters.iter().all(|c| {
        let v = &c.view;
        v.display == DisplayDoc::Mesh && !v.weight_colors && !v.heat_of_selected && v.opacity >= 1.0
    })
}

/// What of a stage has the renderer set up its lights' views and passes anew when it
/// changes: shadows at all, and each lamp's kind (spot) and whether it casts shadows (see
/// [`lamps_kept`]).
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct LightSetup {
    shadows: bool,
    lamps: Vec<(bool, bool)>,
}

impl LightSetup {
    pub fn of(stage: &StageDoc) -> Self {
        Self { shadows: stage.shadows, lamps: stage.lamps.iter().map(|l| (l.spot.is_some(), l.shadows)).collect() }
    }
}

/// Whether a scene lit as `next` is drawn as it should be in its first frame after one lit
/// as `last`: each of its lamps takes the place of one of the last's of its kind (and
/// shadows), so no lamp entity is new (a new lamp is taken up frames after it is spawned;
/// the sun's shadows and lamps removed are taken up at once).
pub fn lamps_kept(last: &LightSetup, next: &LightSetup) -> bool {
    next.lamps.len() <= last.lamps.len() && next.lamps.iter().zip(&last.lamps).all(|(n, l)| n == l)
}

/// The order to draw pictures in (`scenes`: each one's scene, `None` for a picture that is
/// not a scene of its own): the first (the scene the app opens with) first; a data set's
/// scenes then grouped by how they are lit, those lit like the first first, then the groups
/// with more lamps before those with fewer, so that the renderer settles only where a group
/// brings a lamp the last had not.
pub fn drawing_order(scenes: &[Option<&SceneDoc>]) -> Vec<usize> {
    let lights = |k: usize| scenes[k].map(|doc| LightSetup::of(&doc.stage));
    let mut order: Vec<usize> = (0..scenes.len()).collect();
    if let Some(first) = scenes.first().and_then(|_| lights(0)) {
        order[1..].sort_by_cached_key(|&k| {
            let lit = lights(k);
            let lamps = lit.as_ref().map_or(0, |l| l.lamps.len());
            (lit.as_ref() != Some(&first), std::cmp::Reverse(lamps), lit)
        });
    }
    order
}

/// The picture a data set's app best opens with: the first of those with the most lamps
/// (the scenes drawn after it then bring no lamp it lacks; see [`drawing_order`]).
pub fn opening_picture(scenes: &[&SceneDoc]) -> usize {
    let lamps = |k: usize| scenes[k].stage.lamps.len();
    (0..scenes.len()).max_by_key(|&k| (lamps(k), std::cmp::Reverse(k))).unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Mat4, Vec3};
    use marionette_formats::scene::{
        AnimDoc, AttachDoc, CharacterDoc, CharacterId, LampDoc, RetargetDoc, SourceDoc, SpotDoc,
    };

    fn lit(shadows: bool, lamps: &[(bool, bool)]) -> SceneDoc {
        let lamp = |&(spot, shadows): &(bool, bool)| LampDoc {
            spot: spot.then_some(SpotDoc { aim: Vec3::ZERO, angle: 30.0 }),
            shadows,
            ..LampDoc::default()
        };
        let stage = StageDoc { shadows, lamps: lamps.iter().map(lamp).collect(), ..StageDoc::default() };
        SceneDoc { stage, ..SceneDoc::default() }
    }

    fn puppet() -> CharacterDoc {
        CharacterDoc::new(SourceDoc::Embedded("puppet".into()), "puppet")
    }

    /// A scene is captured in its first frame only where none of its lamps is new: the
    /// last's lamps moved, fewer of them, the sun's shadows switched; a lamp added, or one
    /// of another kind or shadows in its place, waits for the renderer to settle.
    #[test]
    fn only_scenes_that_bring_no_new_lamp_are_drawn_at_once() {
        let setup = |shadows, lamps: &[(bool, bool)]| LightSetup::of(&lit(shadows, lamps).stage);
        let studio = setup(true, &[(false, false), (true, false)]);
        assert!(lamps_kept(&studio, &studio));
        assert!(lamps_kept(&studio, &setup(false, &[])));
        assert!(lamps_kept(&studio, &setup(true, &[(false, false)])));
        assert!(lamps_kept(&setup(false, &[]), &setup(true, &[])));
        assert!(!lamps_kept(&setup(true, &[]), &studio));
        assert!(!lamps_kept(&studio, &setup(true, &[(true, false)])));
        assert!(!lamps_kept(&studio, &setup(true, &[(false, true), (true, false)])));
    }

    /// The opened scene first, its lighting's group next, then the groups with more lamps
    /// before those with fewer: every change after the first group takes lamps away.
    #[test]
    fn scenes_are_drawn_in_groups_of_lighting_lamps_going_down() {
        let scenes = [
            lit(true, &[]),
            lit(false, &[]),
            lit(true, &[(false, false), (true, false)]),
            lit(true, &[]),
            lit(true, &[(false, false)]),
            lit(true, &[(false, false), (true, false)]),
        ];
        let order = drawing_order(&scenes.iter().map(Some).collect::<Vec<_>>());
        assert_eq!(order, [0, 3, 2, 5, 4, 1]);
        let lights = |k: usize| LightSetup::of(&scenes[k].stage);
        assert!(order[2..].windows(2).all(|w| lamps_kept(&lights(w[0]), &lights(w[1]))));
        assert_eq!(opening_picture(&scenes.iter().collect::<Vec<_>>()), 2);
        assert_eq!(drawing_order(&[None, Some(&scenes[2]), Some(&scenes[0])]), [0, 1, 2]);
    }

    /// On a GPU small pictures fill a frame with four scenes, large ones with fewer, the
    /// largest with one; on the CPU a frame draws one.
    #[test]
    fn a_frame_draws_as_many_scenes_as_fill_its_pixels() {
        assert_eq!(scenes_a_frame(96, 72, false), 4);
        assert_eq!(scenes_a_frame(640, 480, false), 4);
        assert_eq!(scenes_a_frame(800, 600, false), 2);
        assert_eq!(scenes_a_frame(1280, 720, false), 1);
        assert_eq!(scenes_a_frame(u32::MAX, u32::MAX, false), 1);
        assert_eq!(scenes_a_frame(0, 0, false), 4);
        assert_eq!(scenes_a_frame(96, 72, true), 1);
    }

    /// A scene shares its frame unless the editor's drawings show in it, a character is found
    /// by its id (held by, or moved by, another) or a lamp casts shadows.
    #[test]
    fn only_scenes_of_plain_independent_characters_share_a_frame() {
        let with = |change: &dyn Fn(&mut CharacterDoc)| {
            let mut c = puppet();
            change(&mut c);
            SceneDoc { characters: vec![puppet(), c], ..SceneDoc::default() }
        };
        let moved_by = |from| Some(AnimDoc { retarget: Some(RetargetDoc::of(from)), ..AnimDoc::default() });
        assert!(shares_a_frame(&with(&|_| {})));
        assert!(!shares_a_frame(&with(&|c| c.view.display = DisplayDoc::Skeleton)));
        assert!(!shares_a_frame(&with(&|c| c.view.weight_colors = true)));
        assert!(!shares_a_frame(&with(&|c| c.view.opacity = 0.5)));
        let held = AttachDoc { to: CharacterId(1), joint: "hand".into(), offset: Mat4::IDENTITY };
        assert!(!shares_a_frame(&with(&|c| c.attached = Some(held.clone()))));
        assert!(!shares_a_frame(&with(&|c| c.anim = moved_by(MotionSourceDoc::Character(CharacterId(1))))));
        let walk = MotionSourceDoc::File { path: "walk.bvh".into(), clip: None };
        assert!(shares_a_frame(&with(&|c| c.anim = moved_by(walk.clone()))));
        let mut lamp_lit = with(&|_| {});
        lamp_lit.stage.lamps = vec![LampDoc::default()];
        assert!(shares_a_frame(&lamp_lit));
        lamp_lit.stage.lamps[0].shadows = true;
        assert!(!shares_a_frame(&lamp_lit));
    }

    /// A frame draws the scenes that share one from the next on, as many as it has slots,
    /// and one that cannot share (or a picture that is no scene of its own) alone.
    #[test]
    fn a_scene_that_cannot_share_a_frame_is_drawn_alone() {
        let mut skeleton = puppet();
        skeleton.view.display = DisplayDoc::Skeleton;
        let alone = SceneDoc { characters: vec![skeleton], ..SceneDoc::default() };
        let plain = SceneDoc { characters: vec![puppet()], ..SceneDoc::default() };
        let scenes = [Some(&plain), Some(&plain), Some(&alone), Some(&plain)];
        assert_eq!(drawn_together(scenes, 3), 2);
        assert_eq!(drawn_together(scenes, 1), 1);
        assert_eq!(drawn_together(scenes[2..].iter().copied(), 3), 1);
        assert_eq!(drawn_together([Some(&plain); 5], 4), 4);
        assert_eq!(drawn_together([None, Some(&plain)], 4), 1);
    }
}
