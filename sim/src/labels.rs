//! What each pixel of a frame shows, as a label: the classes of things in the world, the
//! object a solid is, and the legend that numbers them for a scene.
//!
//! Label numbers are fixed for the classes that have one instance (nothing, sky, own body, the
//! floor's paints, walls, the two goals) and follow in order for the objects of a world:
//! cubes, pillars, boards, robots, each by its index in the scenario, then balls. The same world gives the
//! same numbers in every frame.

use serde::Serialize;

/// The classes: each line a class, its name in the legend and whether a world has several
/// things of it (numbered by instance) or one.
macro_rules! classes {
    ($($(#[$doc:meta])* $class:ident = $name:literal, $several:literal;)*) => {
        /// A class of thing a pixel can show.
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
        #[serde(rename_all = "snake_case")]
        pub enum Class {
            $($(#[$doc])* $class,)*
        }

        impl Class {
            /// Every class, in the order of their numbers.
            pub const ALL: &[Class] = &[$(Class::$class,)*];

            /// Its name in the legend (`floor_region`, `cube`, ...).
            pub fn name(self) -> &'static str {
                match self {
                    $(Class::$class => $name,)*
                }
            }

            /// Whether a world may have several things of the class, told apart by instance.
            pub fn has_instances(self) -> bool {
                match self {
                    $(Class::$class => $several,)*
                }
            }
        }
    };
}

classes! {
    /// Outside the mirror's image circle: the camera sees no mirror there.
    Nothing = "nothing", false;
    /// A ray that meets nothing.
    Sky = "sky", false;
    /// The observing robot's own body.
    OwnBody = "own_body", false;
    /// Bare floor inside the floor region (the floor colour).
    FloorRegion = "floor_region", false;
    /// A field line painted on the floor region.
    FloorLine = "floor_line", false;
    /// A mark painted on the floor.
    FloorMark = "floor_mark", false;
    /// Floor outside the floor region.
    FloorOutside = "floor_outside", false;
    /// A wall of the Small-Size field around the floor region.
    FieldWall = "field_wall", false;
    /// A free-standing or corridor wall.
    Wall = "wall", false;
    /// A goal's walls (instance 0: the goal at +x, 1: at -x).
    Goal = "goal", true;
    /// A cube (instance: its index in `[[world.cubes]]`).
    Cube = "cube", true;
    /// A pillar (instance: its index in `[[world.pillars]]`).
    Pillar = "pillar", true;
    /// A striped board (instance: its index in `[[world.boards]]`).
    Board = "board", true;
    /// Another robot (instance: its index in the team).
    Robot = "robot", true;
    /// A ball (instance: which one, 0 for the first). Last of the classes, so that the label
    /// numbers of a world without a ball are those it had before balls existed.
    Ball = "ball", true;
}

impl Class {
    /// Whether the class is the floor (region, lines, marks or outside).
    pub fn is_floor(self) -> bool {
        matches!(
            self,
            Class::FloorRegion | Class::FloorLine | Class::FloorMark | Class::FloorOutside
        )
    }
}

/// The thing a solid is: its class and, for classes with several, which one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
pub struct ObjectId {
    /// Its class.
    pub class: Class,
    /// Which one of its class (0 for the classes that have one).
    pub instance: u32,
}

impl ObjectId {
    /// The one thing of a class that has no instances.
    pub const fn of(class: Class) -> Self {
        Self { class, instance: 0 }
    }

    /// Instance `k` of `class`.
    pub const fn new(class: Class, instance: u32) -> Self {
        Self { class, instance }
    }
}

/// The labels that have fixed numbers, in the order of their numbers from 0.
const FIXED: [ObjectId; 11] = [
    ObjectId::of(Class::Nothing),
    ObjectId::of(Class::Sky),
    ObjectId::of(Class::OwnBody),
    ObjectId::of(Class::FloorRegion),
    ObjectId::of(Class::FloorLine),
    ObjectId::of(Class::FloorMark),
    ObjectId::of(Class::FloorOutside),
    ObjectId::of(Class::FieldWall),
    ObjectId::of(Class::Wall),
    ObjectId::new(Class::Goal, 0),
    ObjectId::new(Class::Goal, 1),
];

/// Label number of [`Class::Nothing`].
pub const NOTHING: u16 = 0;
/// Label number of [`Class::Sky`].
pub const SKY: u16 = 1;
/// Label number of [`Class::OwnBody`].
pub const OWN_BODY: u16 = 2;
/// Label number of [`Class::FloorRegion`].
pub const FLOOR_REGION: u16 = 3;
/// Label number of [`Class::FloorLine`].
pub const FLOOR_LINE: u16 = 4;
/// Label number of [`Class::FloorMark`].
pub const FLOOR_MARK: u16 = 5;
/// Label number of [`Class::FloorOutside`].
pub const FLOOR_OUTSIDE: u16 = 6;

/// One entry of a legend.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LegendEntry {
    /// The label number in the label image.
    pub label: u16,
    /// The class.
    pub class: Class,
    /// Which one of its class.
    pub instance: u32,
    /// A readable name: `cube 2`, `goal +x`, `floor_region`.
    pub name: String,
    /// The colour the label image's palette gives it (sRGB).
    pub rgb: [u8; 3],
}

/// The label numbers of a scene's things.
#[derive(Debug, Clone, PartialEq)]
pub struct Legend {
    objects: Vec<ObjectId>,
}

impl Legend {
    /// The legend of a world holding `objects` (its solids' and robots' objects, in any order,
    /// repeats allowed): the fixed labels, then the objects sorted by class and instance.
    pub fn new(objects: impl IntoIterator<Item = ObjectId>) -> Self {
        let mut extra: Vec<ObjectId> = objects.into_iter().filter(|o| !FIXED.contains(o)).collect();
        extra.sort_unstable();
        extra.dedup();
        Self {
            objects: FIXED.iter().copied().chain(extra).collect(),
        }
    }

    /// The label number of `object` (that of its class's first entry where the legend does not
    /// hold it: a goal or wall always has one).
    pub fn label(&self, object: ObjectId) -> u16 {
        match self.objects.binary_search_by(|o| o.cmp(&object)) {
            Ok(k) => k as u16,
            Err(_) => self
                .objects
                .iter()
                .position(|o| o.class == object.class)
                .unwrap_or(0) as u16,
        }
        .min(self.objects.len() as u16 - 1)
    }

    /// The object of label number `label`, if the legend has it.
    pub fn object(&self, label: u16) -> Option<ObjectId> {
        self.objects.get(label as usize).copied()
    }

    /// How many labels there are.
    pub fn len(&self) -> usize {
        self.objects.len()
    }

    /// Whether there are none (never: the fixed labels are always there).
    pub fn is_empty(&self) -> bool {
        self.objects.is_empty()
    }

    /// Every entry, in label order.
    pub fn entries(&self) -> Vec<LegendEntry> {
        (self.objects.iter().enumerate())
            .map(|(k, o)| LegendEntry {
                label: k as u16,
                class: o.class,
                instance: o.instance,
                name: name(*o),
                rgb: palette_rgb(k as u16),
            })
            .collect()
    }
}

/// A readable name of an object.
fn name(o: ObjectId) -> String {
    match o.class {
        Class::Goal if o.instance == 0 => "goal +x".into(),
        Class::Goal => "goal -x".into(),
        Class::Ball if o.instance == 0 => "ball".into(),
        c if c.has_instances() => format!("{} {}", c.name(), o.instance),
        c => c.name().into(),
    }
}

/// The palette colour of a label: fixed, telling colours for the fixed labels, and for the
/// objects a sequence of well-spread hues (golden-ratio steps).
pub fn palette_rgb(label: u16) -> [u8; 3] {
    const FIXED_RGB: [[u8; 3]; 11] = [
        [0, 0, 0],       // nothing
        [135, 190, 235], // sky
        [90, 90, 90],    // own body
        [40, 160, 70],   // floor region
        [250, 250, 250], // floor line
        [250, 140, 200], // floor mark
        [120, 95, 70],   // floor outside
        [200, 200, 160], // field wall
        [170, 170, 200], // wall
        [240, 200, 20],  // goal +x
        [30, 70, 230],   // goal -x
    ];
    if let Some(c) = FIXED_RGB.get(label as usize) {
        return *c;
    }
    let h = (label as f64 * 0.618_033_988_75).fract() * 6.0;
    let (s, v) = (0.75, 0.9);
    let f = h.fract();
    let (p, q, t) = (v * (1.0 - s), v * (1.0 - s * f), v * (1.0 - s * (1.0 - f)));
    let rgb = match h as u32 {
        0 => (v, t, p),
        1 => (q, v, p),
        2 => (p, v, t),
        3 => (p, q, v),
        4 => (t, p, v),
        _ => (v, p, q),
    };
    [rgb.0, rgb.1, rgb.2].map(|c| (c * 255.0).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_legend_numbers_fixed_labels_first_then_objects_in_order() {
        let legend = Legend::new([
            ObjectId::new(Class::Robot, 1),
            ObjectId::new(Class::Cube, 2),
            ObjectId::new(Class::Cube, 0),
            ObjectId::of(Class::Wall),
            ObjectId::new(Class::Cube, 2),
        ]);
        assert_eq!(legend.len(), 14);
        assert_eq!(legend.label(ObjectId::of(Class::Sky)), SKY);
        assert_eq!(legend.label(ObjectId::of(Class::FloorRegion)), FLOOR_REGION);
        assert_eq!(legend.label(ObjectId::new(Class::Cube, 0)), 11);
        assert_eq!(legend.label(ObjectId::new(Class::Cube, 2)), 12);
        assert_eq!(legend.label(ObjectId::new(Class::Robot, 1)), 13);
        assert_eq!(legend.object(12), Some(ObjectId::new(Class::Cube, 2)));
        let entries = legend.entries();
        assert_eq!(entries[12].name, "cube 2");
        assert_eq!(entries[9].name, "goal +x");
        // Every label a different colour.
        let mut colours: Vec<[u8; 3]> = entries.iter().map(|e| e.rgb).collect();
        colours.sort_unstable();
        colours.dedup();
        assert_eq!(colours.len(), entries.len());
    }

    #[test]
    fn a_ball_comes_after_every_other_object_and_leaves_their_labels_as_they_were() {
        let others = [
            ObjectId::new(Class::Cube, 0),
            ObjectId::new(Class::Board, 1),
            ObjectId::new(Class::Robot, 2),
        ];
        let before = Legend::new(others);
        let with_balls = Legend::new(
            [ObjectId::new(Class::Ball, 1), ObjectId::new(Class::Ball, 0)]
                .into_iter()
                .chain(others),
        );
        for o in others {
            assert_eq!(with_balls.label(o), before.label(o), "{o:?}");
        }
        let ball = with_balls.label(ObjectId::new(Class::Ball, 0));
        assert_eq!(ball as usize, before.len());
        assert_eq!(with_balls.label(ObjectId::new(Class::Ball, 1)), ball + 1);
        let entries = with_balls.entries();
        assert_eq!(entries[ball as usize].name, "ball");
        assert_eq!(entries[ball as usize + 1].name, "ball 1");
    }
}
