//! The 3-D scene a sensor sees, as flat `f32` arrays laid out for the GPU: the floor (floor
//! region rectangles, field lines), boxes (walls, cubes, boards), upright cylinders (pillars,
//! robots, the observer's own body), quadrilateral prisms (mitred wall pieces), spheres (a ball)
//! and the light.
//!
//! Both tracers, the WGSL one and the CPU reference, read exactly these arrays.

use crate::color::Rgb;
use crate::floor_marks::MarkShape;
use crate::labels::{Legend, ObjectId};
use crate::layout::Layout;
use crate::shapes::{Solid, SolidShape};
use crate::sphere::Sphere;
use crate::world::World;
use bytemuck::{Pod, Zeroable};

/// A box: footprint rectangle rotated about z, from `base` to `top` above the floor.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct BoxPrim {
    /// centre x, centre y, half extent x, half extent y (mm).
    pub geom: [f32; 4],
    /// cos(angle), sin(angle), base height, top height.
    pub frame: [f32; 4],
    /// r, g, b (0..1), stripe board index or -1.
    pub color: [f32; 4],
}

/// An upright cylinder standing on the floor.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct CylinderPrim {
    /// centre x, centre y, radius, top height (mm).
    pub geom: [f32; 4],
    /// r, g, b (0..1) of the side, unused.
    pub color: [f32; 4],
    /// r, g, b (0..1) of the top face (a robot's marking; the side's colour otherwise), unused.
    pub top: [f32; 4],
}

/// An upright prism on a convex quadrilateral (corners counter-clockwise; a triangle repeats a
/// corner), standing on the floor.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct QuadPrim {
    /// Corners 0 and 1: x0, y0, x1, y1 (mm).
    pub c01: [f32; 4],
    /// Corners 2 and 3: x2, y2, x3, y3 (mm).
    pub c23: [f32; 4],
    /// Top height (mm), unused, unused, unused.
    pub z: [f32; 4],
    /// r, g, b (0..1), unused.
    pub color: [f32; 4],
}

impl QuadPrim {
    /// Corner `i` (0..4).
    pub fn corner(&self, i: usize) -> [f32; 2] {
        match i {
            0 => [self.c01[0], self.c01[1]],
            1 => [self.c01[2], self.c01[3]],
            2 => [self.c23[0], self.c23[1]],
            _ => [self.c23[2], self.c23[3]],
        }
    }
}

/// A sphere, anywhere above (or on) the floor.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SpherePrim {
    /// centre x, centre y, centre height, radius (mm).
    pub geom: [f32; 4],
    /// r, g, b (0..1), unused.
    pub color: [f32; 4],
}

impl SpherePrim {
    /// The primitive of `sphere`.
    pub fn of(sphere: &Sphere) -> Self {
        let [x, y, z] = sphere.center_mm;
        Self {
            geom: [x as f32, y as f32, z as f32, sphere.radius_mm as f32],
            color: rgb4(sphere.rgb, 0.0),
        }
    }
}

/// The stripes of a board: a range of `stripe_edges` and the two alternating colours.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct BoardPrim {
    /// first edge index, edge count, unused, unused.
    pub range: [u32; 4],
    /// Colour of even stripes.
    pub color_a: [f32; 4],
    /// Colour of odd stripes.
    pub color_b: [f32; 4],
}

/// A floor-region rectangle, or a mark painted on the floor (a square or a disc).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct FloorRectPrim {
    /// centre x, centre y, half size x (a disc's radius), half size y.
    pub geom: [f32; 4],
    /// cos(angle), sin(angle), kind ([`FLOOR_REGION`], [`SQUARE_MARK`], [`DISC_MARK`]), unused.
    pub frame: [f32; 4],
    /// A mark's colour r, g, b (0..1), unused.
    pub color: [f32; 4],
}

/// `FloorRectPrim::frame[2]` of a floor-region rectangle.
pub const FLOOR_REGION: f32 = 0.0;
/// `FloorRectPrim::frame[2]` of a square (or rectangular) mark.
pub const SQUARE_MARK: f32 = 1.0;
/// `FloorRectPrim::frame[2]` of a disc mark.
pub const DISC_MARK: f32 = 2.0;

/// The scene's lists, as the kernels read them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneList {
    /// [`Scene::boxes`].
    Boxes,
    /// [`Scene::cylinders`].
    Cylinders,
    /// [`Scene::boards`].
    Boards,
    /// [`Scene::stripe_edges`].
    StripeEdges,
    /// [`Scene::floor_rects`].
    FloorRects,
    /// [`Scene::quads`].
    Quads,
    /// [`Scene::spheres`].
    Spheres,
}

impl SceneList {
    /// Its name: its array's in `trace.wgsl`, its GPU buffer's label.
    pub fn name(self) -> &'static str {
        match self {
            SceneList::Boxes => "boxes",
            SceneList::Cylinders => "cylinders",
            SceneList::Boards => "boards",
            SceneList::StripeEdges => "stripe_edges",
            SceneList::FloorRects => "floor_rects",
            SceneList::Quads => "quads",
            SceneList::Spheres => "spheres",
        }
    }

    /// The WGSL type of its elements (the structs of `trace.wgsl`, twins of this file's).
    pub fn wgsl_type(self) -> &'static str {
        match self {
            SceneList::Boxes => "BoxPrim",
            SceneList::Cylinders => "CylinderPrim",
            SceneList::Boards => "BoardPrim",
            SceneList::StripeEdges => "f32",
            SceneList::FloorRects => "FloorRectPrim",
            SceneList::Quads => "QuadPrim",
            SceneList::Spheres => "SpherePrim",
        }
    }

    /// The bytes of one of its elements.
    pub fn element_bytes(self) -> usize {
        match self {
            SceneList::Boxes => std::mem::size_of::<BoxPrim>(),
            SceneList::Cylinders => std::mem::size_of::<CylinderPrim>(),
            SceneList::Boards => std::mem::size_of::<BoardPrim>(),
            SceneList::StripeEdges => std::mem::size_of::<f32>(),
            SceneList::FloorRects => std::mem::size_of::<FloorRectPrim>(),
            SceneList::Quads => std::mem::size_of::<QuadPrim>(),
            SceneList::Spheres => std::mem::size_of::<SpherePrim>(),
        }
    }
}

/// One row of [`SCENE_LISTS`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ListLayout {
    /// The list.
    pub list: SceneList,
    /// Its storage binding in `trace.wgsl`'s group 0.
    pub binding: u32,
    /// Where a frame's first element of it goes among the frame's offset words (`Frame.offsets`,
    /// `offsets2`, `offsets3` of `trace.wgsl`, as one array of twelve).
    pub offset_word: usize,
    /// The elements the GPU's buffer has room for at the start (never empty: a binding needs
    /// bytes).
    pub initial_room: u64,
}

/// The table the GPU's buffers, bindings and per-frame offsets are laid out from: one row a
/// list of the scene. (Offset words 6 and 7 are a frame's first pixel and its noise's key.)
pub const SCENE_LISTS: [ListLayout; 7] = [
    ListLayout {
        list: SceneList::Boxes,
        binding: 2,
        offset_word: 0,
        initial_room: 64,
    },
    ListLayout {
        list: SceneList::Cylinders,
        binding: 3,
        offset_word: 1,
        initial_room: 16,
    },
    ListLayout {
        list: SceneList::Boards,
        binding: 4,
        offset_word: 2,
        initial_room: 4,
    },
    ListLayout {
        list: SceneList::StripeEdges,
        binding: 5,
        offset_word: 3,
        initial_room: 64,
    },
    ListLayout {
        list: SceneList::FloorRects,
        binding: 6,
        offset_word: 4,
        initial_room: 8,
    },
    ListLayout {
        list: SceneList::Quads,
        binding: 8,
        offset_word: 5,
        initial_room: 16,
    },
    ListLayout {
        list: SceneList::Spheres,
        binding: 11,
        offset_word: 8,
        initial_room: 16,
    },
];

/// The primitives a ray may meet, in the order of their ranks: a pixel's code is its
/// primitive's rank, from 1 for the first box (0 is the floor). Every kernel (the reference,
/// the packets, AVX2, `trace.wgsl`) and the legend ([`Scene::objects`]) follow it.
pub const RANKED: [SceneList; 4] = [
    SceneList::Boxes,
    SceneList::Quads,
    SceneList::Cylinders,
    SceneList::Spheres,
];

/// Where `list` is in [`RANKED`] (`RANKED.len()` for a list a ray does not meet).
pub const fn rank_slot(list: SceneList) -> usize {
    let mut i = 0;
    while i < RANKED.len() {
        if RANKED[i] as u8 == list as u8 {
            return i;
        }
        i += 1;
    }
    RANKED.len()
}

/// Everything about the scene that is not a list.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Pod, Zeroable)]
pub struct SceneGlobals {
    /// Field: A1, B, line width, centre circle radius.
    pub field: [f32; 4],
    /// field present (0/1), any floor region (0/1), box count, cylinder count.
    pub flags: [u32; 4],
    /// floor rectangle and mark count, board count, quad count, sphere count.
    pub counts: [u32; 4],
    /// Floor region colour.
    pub floor_rgb: [f32; 4],
    /// Floor colour outside the region.
    pub outside_rgb: [f32; 4],
    /// Field line colour.
    pub line_rgb: [f32; 4],
    /// Colour of rays that hit nothing.
    pub sky_rgb: [f32; 4],
    /// Unit direction toward the light (x, y, z), ambient term.
    pub light: [f32; 4],
    /// Diffuse term, normalisation so the floor shows its own colour, unused, unused.
    pub light2: [f32; 4],
    /// Defense areas' lines: |x| of the front line's outer and inner edges, |y| of the side
    /// lines' outer and inner edges ([`crate::FieldLines::defense_edges_mm`]; the sides' -1
    /// when there are none).
    pub field2: [f32; 4],
}

/// The scene of one frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Scalars.
    pub globals: SceneGlobals,
    /// Boxes.
    pub boxes: Vec<BoxPrim>,
    /// Cylinders.
    pub cylinders: Vec<CylinderPrim>,
    /// Quadrilateral prisms.
    pub quads: Vec<QuadPrim>,
    /// Boards.
    pub boards: Vec<BoardPrim>,
    /// Stripe edges of all boards, as fractions of the board length.
    pub stripe_edges: Vec<f32>,
    /// Floor-region rectangles.
    pub floor_rects: Vec<FloorRectPrim>,
    /// Spheres.
    pub spheres: Vec<SpherePrim>,
    /// What each box, quad prism, cylinder and sphere is, in that order (a primitive's rank in
    /// the scene's order less one): the per-pixel labels' source.
    pub objects: Vec<ObjectId>,
}

fn unit_frame(angle_deg: f64, kind: f32) -> [f32; 4] {
    let a = angle_deg.to_radians();
    [a.cos() as f32, a.sin() as f32, kind, 0.0]
}

fn rgb4(c: Rgb, w: f32) -> [f32; 4] {
    let [r, g, b] = c.to_unit();
    [r, g, b, w]
}

/// Ambient and diffuse weights of the light, and its direction (from the floor toward it).
const AMBIENT: f32 = 0.45;
const DIFFUSE: f32 = 0.55;
const LIGHT_DIR: [f32; 3] = [0.35, 0.25, 0.9];
const SKY_RGB: Rgb = Rgb([150, 160, 175]);

/// The floor's rectangles of `layout`: its floor region's, then its marks; and whether it has a
/// floor region.
fn floor_rects(layout: &Layout) -> (Vec<FloorRectPrim>, bool) {
    let regions = layout.all_floor_rects();
    let any_region = !regions.is_empty();
    let mut floor_rects: Vec<FloorRectPrim> = regions
        .iter()
        .map(|r| FloorRectPrim {
            geom: [
                r.center_mm[0] as f32,
                r.center_mm[1] as f32,
                (r.size_mm[0] / 2.0) as f32,
                (r.size_mm[1] / 2.0) as f32,
            ],
            frame: unit_frame(r.angle_deg, FLOOR_REGION),
            color: [0.0; 4],
        })
        .collect();
    floor_rects.extend(layout.all_floor_marks().iter().map(|m| {
        let h = (m.size_mm / 2.0) as f32;
        let kind = match m.shape {
            MarkShape::Square => SQUARE_MARK,
            MarkShape::Disc => DISC_MARK,
        };
        FloorRectPrim {
            geom: [m.center_mm[0] as f32, m.center_mm[1] as f32, h, h],
            frame: unit_frame(m.angle_deg, kind),
            color: rgb4(m.rgb, 0.0),
        }
    }));
    (floor_rects, any_region)
}

/// The list a solid's primitive goes in.
fn list_of(shape: &SolidShape) -> SceneList {
    match shape {
        SolidShape::Box { .. } => SceneList::Boxes,
        SolidShape::Quad { .. } => SceneList::Quads,
        SolidShape::Cylinder { .. } => SceneList::Cylinders,
    }
}

/// What each solid is, in the order of the primitives' ranks ([`RANKED`]).
fn objects_by_rank(solids: &[&Solid]) -> Vec<ObjectId> {
    RANKED
        .iter()
        .flat_map(|&list| solids.iter().filter(move |s| list_of(&s.shape) == list))
        .map(|s| s.object)
        .collect()
}

impl SceneGlobals {
    /// The scalars of a scene of `layout` (`any_region`: whether it has floor-region
    /// rectangles) with `[boxes, cylinders, floor rectangles and marks, boards, quads]`.
    fn of(layout: &Layout, any_region: bool, counts: [u32; 5]) -> Self {
        let [boxes, cylinders, floor_rects, boards, quads] = counts;
        let n = (LIGHT_DIR[0] * LIGHT_DIR[0]
            + LIGHT_DIR[1] * LIGHT_DIR[1]
            + LIGHT_DIR[2] * LIGHT_DIR[2])
            .sqrt();
        let l = [LIGHT_DIR[0] / n, LIGHT_DIR[1] / n, LIGHT_DIR[2] / n];
        let field = layout.field_lines();
        Self {
            field: field.map_or([0.0; 4], |f| {
                [
                    f.half_length_mm as f32,
                    f.half_width_mm as f32,
                    f.line_width_mm as f32,
                    f.centre_circle_radius_mm as f32,
                ]
            }),
            flags: [field.is_some() as u32, any_region as u32, boxes, cylinders],
            counts: [floor_rects, boards, quads, 0],
            floor_rgb: rgb4(layout.floor_rgb, 0.0),
            outside_rgb: rgb4(layout.outside_rgb, 0.0),
            line_rgb: rgb4(layout.line_rgb, 0.0),
            sky_rgb: rgb4(SKY_RGB, 0.0),
            light: [l[0], l[1], l[2], AMBIENT],
            light2: [DIFFUSE, 1.0 / (AMBIENT + DIFFUSE * l[2]), 0.0, 0.0],
            field2: field.map_or([0.0, 0.0, -1.0, -1.0], |f| {
                f.defense_edges_mm().map(|v| v as f32)
            }),
        }
    }
}

impl Scene {
    /// The scene of a layout with extra solids (robots, the observer's body).
    pub fn new(layout: &Layout, extra: &[Solid]) -> Self {
        Self::from_solids(layout, layout.solids().iter().chain(extra))
    }

    /// The scene a world shows now: its layout, its solids, every robot and the ball.
    pub fn of_world(world: &World) -> Self {
        Self::from_solids(
            world.layout(),
            world.solids().iter().chain(&world.robot_solids(None)),
        )
        .with_spheres(&world.spheres())
    }

    /// The scene of a layout's floor with the given solids (which must include the layout's own
    /// walls, cubes, pillars and boards).
    fn from_solids<'a>(layout: &Layout, solids: impl Iterator<Item = &'a Solid>) -> Self {
        let mut boxes = Vec::new();
        let mut cylinders = Vec::new();
        let mut quads = Vec::new();
        let solids: Vec<&Solid> = solids.collect();
        for s in &solids {
            match s.shape {
                SolidShape::Box {
                    center_mm,
                    half_extents_mm,
                    angle_rad,
                } => boxes.push(BoxPrim {
                    geom: [
                        center_mm.x as f32,
                        center_mm.y as f32,
                        half_extents_mm.x as f32,
                        half_extents_mm.y as f32,
                    ],
                    frame: [
                        angle_rad.cos() as f32,
                        angle_rad.sin() as f32,
                        s.base_mm as f32,
                        s.height_mm as f32,
                    ],
                    color: rgb4(s.rgb, s.board.map_or(-1.0, |b| b as f32)),
                }),
                SolidShape::Cylinder {
                    center_mm,
                    radius_mm,
                } => cylinders.push(CylinderPrim {
                    geom: [
                        center_mm.x as f32,
                        center_mm.y as f32,
                        radius_mm as f32,
                        s.height_mm as f32,
                    ],
                    color: rgb4(s.rgb, 0.0),
                    top: rgb4(s.top_rgb.unwrap_or(s.rgb), 0.0),
                }),
                SolidShape::Quad { corners_mm: c } => quads.push(QuadPrim {
                    c01: [c[0].x, c[0].y, c[1].x, c[1].y].map(|v| v as f32),
                    c23: [c[2].x, c[2].y, c[3].x, c[3].y].map(|v| v as f32),
                    z: [s.height_mm as f32, 0.0, 0.0, 0.0],
                    color: rgb4(s.rgb, 0.0),
                }),
            }
        }
        let mut boards = Vec::new();
        let mut stripe_edges = Vec::new();
        for b in layout.stripes() {
            boards.push(BoardPrim {
                range: [stripe_edges.len() as u32, b.edges.len() as u32, 0, 0],
                color_a: rgb4(b.rgb_a, 0.0),
                color_b: rgb4(b.rgb_b, 0.0),
            });
            stripe_edges.extend(b.edges.iter().map(|&e| e as f32));
        }
        let (floor_rects, any_region) = floor_rects(layout);
        let counts = [
            boxes.len(),
            cylinders.len(),
            floor_rects.len(),
            boards.len(),
            quads.len(),
        ];
        let globals = SceneGlobals::of(layout, any_region, counts.map(|n| n as u32));
        Self {
            globals,
            boxes,
            cylinders,
            quads,
            boards,
            stripe_edges,
            floor_rects,
            spheres: Vec::new(),
            objects: objects_by_rank(&solids),
        }
    }

    /// The scene with `spheres` added after those it has (their ranks after every other
    /// primitive's, their objects last in [`Scene::objects`]).
    pub fn with_spheres(mut self, spheres: &[Sphere]) -> Self {
        self.spheres.extend(spheres.iter().map(SpherePrim::of));
        self.objects.extend(spheres.iter().map(|s| s.object));
        self.globals.counts[3] = self.spheres.len() as u32;
        self
    }

    /// A list's elements, as the bytes the GPU reads, and how many there are.
    pub fn list(&self, list: SceneList) -> (&[u8], usize) {
        fn bytes<T: Pod>(v: &[T]) -> (&[u8], usize) {
            (bytemuck::cast_slice(v), v.len())
        }
        match list {
            SceneList::Boxes => bytes(&self.boxes),
            SceneList::Cylinders => bytes(&self.cylinders),
            SceneList::Boards => bytes(&self.boards),
            SceneList::StripeEdges => bytes(&self.stripe_edges),
            SceneList::FloorRects => bytes(&self.floor_rects),
            SceneList::Quads => bytes(&self.quads),
            SceneList::Spheres => bytes(&self.spheres),
        }
    }

    /// The rank of the first primitive of each list of [`RANKED`] (from 1; 0 is the floor).
    pub fn first_ranks(&self) -> [u32; RANKED.len()] {
        let mut next = 1;
        RANKED.map(|list| {
            let first = next;
            next += self.list(list).1 as u32;
            first
        })
    }

    /// The legend of the labels of this scene's things.
    pub fn legend(&self) -> Legend {
        Legend::new(self.objects.iter().copied())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Cube, Pillar};

    #[test]
    fn the_lists_table_gives_each_list_its_own_binding_and_offset_word() {
        let mut bindings: Vec<u32> = SCENE_LISTS.iter().map(|r| r.binding).collect();
        // Frames 0, pixels 7, the noise table 9 and the truth 10 are bound beside the lists.
        bindings.extend([0, 7, 9, 10]);
        bindings.sort_unstable();
        bindings.dedup();
        assert_eq!(bindings.len(), SCENE_LISTS.len() + 4);
        let mut words: Vec<usize> = SCENE_LISTS.iter().map(|r| r.offset_word).collect();
        words.extend([6, 7]);
        words.sort_unstable();
        words.dedup();
        assert_eq!(words.len(), SCENE_LISTS.len() + 2);
        assert!(words.iter().all(|&w| w < 12));
        for list in RANKED {
            assert!(SCENE_LISTS.iter().any(|r| r.list == list), "{list:?}");
            assert_eq!(RANKED[rank_slot(list)], list);
        }
        assert_eq!(rank_slot(SceneList::Boards), RANKED.len());
    }

    #[test]
    fn a_primitives_rank_finds_its_object_in_the_legend_order() {
        let layout = Layout {
            cubes: vec![Cube {
                center_mm: [500.0, 0.0],
                size_mm: 100.0,
                angle_deg: 0.0,
                rgb: Rgb([40, 40, 40]),
            }],
            pillars: vec![Pillar {
                center_mm: [0.0, 500.0],
                radius_mm: 50.0,
                height_mm: 300.0,
                rgb: Rgb([200, 0, 0]),
            }],
            ..Layout::default()
        };
        let sphere = Sphere {
            center_mm: [0.0, -500.0, 21.5],
            radius_mm: 21.5,
            rgb: Rgb([255, 120, 0]),
            object: ObjectId::of(crate::labels::Class::Ball),
        };
        let scene = Scene::new(&layout, &[]).with_spheres(&[sphere]);
        let first = scene.first_ranks();
        // Ranks count from 1; the objects are listed from rank 1 on.
        let at = |list: SceneList| scene.objects[first[rank_slot(list)] as usize - 1];
        assert_eq!(at(SceneList::Boxes).class, crate::labels::Class::Cube);
        assert_eq!(at(SceneList::Cylinders).class, crate::labels::Class::Pillar);
        assert_eq!(at(SceneList::Spheres).class, crate::labels::Class::Ball);
        let (bytes, n) = scene.list(SceneList::Spheres);
        assert_eq!((bytes.len(), n), (SceneList::Spheres.element_bytes(), 1));
    }
}
