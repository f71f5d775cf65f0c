//! What a joint's name says about it: its side and the standard bone it may be, read from
//! the name families humanoid rigs use (Mixamo `mixamorig:LeftUpLeg`, MotionBuilder/HumanIK
//! `LeftForeArm`, CMU `LHipJoint`/`LThumb`, Unity/Bandai-Namco `UpperArm_L`, Unreal
//! `thigh_l`/`calf_l`/`ball_l`, Rigify `DEF-upper_arm.L`, VRoid `J_Bip_L_UpperArm`, Daz
//! `lShldrBend`, SMPL `L_Collar`, SMPL-X `left_index1`, 3ds Max Biped `Bip01 L Finger1`),
//! and which joints are no part of the body (IK and control joints, twist and roll joints,
//! ends, capes, hair, tails, weapons).

/// A side of the body.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    Left,
    Right,
}

/// The bone a name says a joint is (sides apart).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    Hips,
    Spine,
    Neck,
    Head,
    Clavicle,
    /// `shoulder`: the clavicle where an upper arm is named below it, else the upper arm.
    Shoulder,
    UpperArm,
    LowerArm,
    /// `hand` or `wrist` (a hand named below a wrist is a palm).
    Hand,
    UpperLeg,
    /// A sided `hip`: the upper leg where no better name is found.
    SidedHip,
    LowerLeg,
    /// `ankle`.
    Ankle,
    Foot,
    Toes,
    /// A finger: thumb, index, middle, ring, little (0–4).
    Finger(usize),
}

/// What a name says: its side, its bone, and whether the joint is no part of the body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct NameSays {
    pub side: Option<Side>,
    pub role: Option<Role>,
    pub excluded: bool,
}

/// Words that mark a joint as no part of the body: controls, IK goals, twist and roll
/// joints, ends, and what hangs on a body (capes, hair, tails, weapons, clothes).
const EXCLUDED: &[&str] = &[
    "end",
    "nub",
    "site",
    "tip",
    "top",
    "ctrl",
    "ctl",
    "control",
    "controller",
    "ik",
    "pole",
    "pv",
    "target",
    "tgt",
    "roll",
    "twist",
    "tw",
    "heel",
    "effector",
    "eff",
    "helper",
    "aux",
    "mch",
    "wgt",
    "cape",
    "cloak",
    "hair",
    "tail",
    "skirt",
    "cloth",
    "coat",
    "breast",
    "weapon",
    "sword",
    "gun",
    "shield",
    "prop",
    "attach",
    "socket",
    "sec",
    "dummy",
    "null",
    "locator",
    "ponytail",
    "ribbon",
    "scarf",
    "bag",
    "hood",
    "hat",
    "eye",
    "eyes",
    "jaw",
    "tongue",
    "teeth",
    "ear",
    "lid",
    "brow",
    "mouth",
    "lip",
    "nose",
    "cheek",
    "bust",
    "spring",
    "phys",
    "jiggle",
    "adjust",
    "share",
    "palm",
    "carpal",
    "metacarpal",
    "fk",
    "org",
    "mstr",
    "master",
    "vis",
    "tweak",
    "pivot",
    "gizmo",
];

/// Words that carry nothing: rig prefixes and filler.
const NOISE: &[&str] = &[
    "def",
    "j",
    "jnt",
    "joint",
    "bip",
    "biped",
    "bn",
    "bone",
    "b",
    "c",
    "mixamorig",
    "cc",
    "base",
    "drv",
    "sk",
    "skl",
    "skel",
    "rig",
    "bend",
    "ctr",
    "center",
    "centre",
    "valvebiped",
    "bip001",
];

/// Whole-name words of each role (after side, noise and digits are taken off).
const ROLES: &[(&str, Role)] = &[
    ("hips", Role::Hips),
    ("hip", Role::Hips),
    ("pelvis", Role::Hips),
    ("spine", Role::Spine),
    ("abdomen", Role::Spine),
    ("abdomenlower", Role::Spine),
    ("lowerback", Role::Spine),
    ("waist", Role::Spine),
    ("neck", Role::Neck),
    ("necklower", Role::Neck),
    ("lowerneck", Role::Neck),
    ("neckupper", Role::Neck),
    ("upperneck", Role::Neck),
    ("head", Role::Head),
    ("clavicle", Role::Clavicle),
    ("clav", Role::Clavicle),
    ("collar", Role::Clavicle),
    ("collarbone", Role::Clavicle),
    ("shoulder", Role::Shoulder),
    ("upperarm", Role::UpperArm),
    ("uparm", Role::UpperArm),
    ("arm", Role::UpperArm),
    ("humerus", Role::UpperArm),
    ("shldr", Role::UpperArm),
    ("forearm", Role::LowerArm),
    ("lowerarm", Role::LowerArm),
    ("loarm", Role::LowerArm),
    ("lowarm", Role::LowerArm),
    ("elbow", Role::LowerArm),
    ("radius", Role::LowerArm),
    ("ulna", Role::LowerArm),
    ("hand", Role::Hand),
    ("wrist", Role::Hand),
    ("upleg", Role::UpperLeg),
    ("upperleg", Role::UpperLeg),
    ("uprleg", Role::UpperLeg),
    ("thigh", Role::UpperLeg),
    ("femur", Role::UpperLeg),
    ("leg", Role::LowerLeg),
    ("lowerleg", Role::LowerLeg),
    ("loleg", Role::LowerLeg),
    ("lowleg", Role::LowerLeg),
    ("calf", Role::LowerLeg),
    ("shin", Role::LowerLeg),
    ("knee", Role::LowerLeg),
    ("tibia", Role::LowerLeg),
    ("ankle", Role::Ankle),
    ("foot", Role::Foot),
    ("toe", Role::Toes),
    ("toes", Role::Toes),
    ("ball", Role::Toes),
    ("metatarsals", Role::Toes),
];

/// Words naming each finger, thumb first.
const FINGERS: [&[&str]; 5] =
    [&["thumb", "pollex"], &["index", "pointer"], &["middle", "mid"], &["ring"], &["little", "pinky", "small"]];

/// Reads a joint's name.
pub fn read(name: &str) -> NameSays {
    let words = words(name);
    let mut says = NameSays::default();
    let mut core = String::new();
    let biped_finger = words.iter().any(|w| w == "finger");
    for (k, w) in words.iter().enumerate() {
        match w.as_str() {
            "l" | "left" | "lft" => says.side = Some(Side::Left),
            "r" | "right" | "rgt" | "rt" => says.side = Some(Side::Right),
            _ if EXCLUDED.contains(&w.as_str()) => says.excluded = true,
            _ if NOISE.contains(&w.as_str()) => {}
            _ if w.bytes().all(|b| b.is_ascii_digit()) => {
                // 3ds Max Biped: `Finger0` is the thumb, `Finger12` the index's third.
                if biped_finger && k > 0 && words[k - 1] == "finger" && says.role.is_none() {
                    let finger = usize::from(w.as_bytes()[0] - b'0');
                    says.role = (finger < 5).then_some(Role::Finger(finger));
                }
            }
            _ => {
                if let Some(f) = FINGERS.iter().position(|names| names.contains(&w.as_str())) {
                    says.role.get_or_insert(Role::Finger(f));
                }
                core.push_str(w);
            }
        }
    }
    if says.excluded {
        says.role = None;
        return says;
    }
    if matches!(says.role, Some(Role::Finger(_))) {
        return says;
    }
    says.role = ROLES.iter().find(|(word, _)| *word == core).map(|(_, role)| *role);
    if says.role == Some(Role::Hips) && says.side.is_some() {
        says.role = if core == "pelvis" { None } else { Some(Role::SidedHip) };
    }
    says
}

/// The names with the prefix they all share taken off (`Character1_`), where it ends at a
/// separator and leaves every name something.
pub fn without_common_prefix(names: &[&str]) -> Vec<String> {
    let Some(first) = names.first() else { return Vec::new() };
    let mut common = first.len();
    for name in &names[1..] {
        common = common.min(first.bytes().zip(name.bytes()).take_while(|(a, b)| a == b).count());
    }
    let cut = first[..common].rfind(['_', ':', '|', ' ', '.', '-']).map_or(0, |k| k + 1);
    let cut = if names.iter().all(|n| n.len() > cut && n.is_char_boundary(cut)) { cut } else { 0 };
    names.iter().map(|n| n[cut..].to_string()).collect()
}

/// A name cut into lowercase words: at separators, case changes (`LeftUpLeg`, `LThumb`)
/// and digits, after a namespace (`mixamorig:`, `Armature|`); a word that is a side letter
/// glued to a known word (`lfemur`, `rhand`) is cut after the letter.
pub fn words(name: &str) -> Vec<String> {
    let base = name.rsplit([':', '|']).next().unwrap_or(name);
    let mut out: Vec<String> = Vec::new();
    for piece in base.split(|c: char| !c.is_ascii_alphanumeric()) {
        let chars: Vec<char> = piece.chars().collect();
        let mut word = String::new();
        for (i, &c) in chars.iter().enumerate() {
            let prev = i.checked_sub(1).map(|p| chars[p]);
            let next = chars.get(i + 1).copied();
            let cut = match prev {
                None => false,
                Some(p) => {
                    (p.is_ascii_lowercase() && c.is_ascii_uppercase())
                        || (p.is_ascii_uppercase()
                            && c.is_ascii_uppercase()
                            && next.is_some_and(|n| n.is_ascii_lowercase()))
                        || (p.is_ascii_digit() != c.is_ascii_digit())
                }
            };
            if cut && !word.is_empty() {
                out.push(std::mem::take(&mut word).to_ascii_lowercase());
            }
            word.push(c);
        }
        if !word.is_empty() {
            out.push(word.to_ascii_lowercase());
        }
    }
    let known = |w: &str| {
        ROLES.iter().any(|(r, _)| *r == w)
            || FINGERS.iter().any(|f| f.contains(&w))
            || ["hipjoint", "fingers"].contains(&w)
    };
    let mut split = Vec::with_capacity(out.len());
    for w in out {
        let glued = w.len() > 3 && (w.starts_with('l') || w.starts_with('r')) && !known(&w) && known(&w[1..]);
        if glued {
            split.push(w[..1].to_string());
            split.push(w[1..].to_string());
        } else {
            split.push(w);
        }
    }
    // `hipjoint` (CMU's `LHipJoint`, its ASF's `lhipjoint`) is the pelvis-side bone from the
    // hips' centre to the hip socket: a sided pelvis, never the upper leg.
    split.into_iter().map(|w| if w == "hipjoint" { "pelvis".into() } else { w }).collect()
}
