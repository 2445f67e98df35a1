//! ssl-vision's messages (github.com/RoboCup-SSL/ssl-vision, proto2, no package), written from
//! its documentation with its field numbers: detections and the field's geometry. Units are
//! ssl-vision's: millimetres, radians, Unix seconds.

/// Who sent a packet (`SSL_Source`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, prost::Enumeration)]
#[repr(i32)]
pub enum Source {
    /// Not set.
    Unknown = 0,
    /// Another sender.
    Other = 1,
    /// ssl-vision.
    SslVision = 2,
    /// A vision processor.
    VisionProcessor = 3,
    /// grSim.
    Grsim = 4,
    /// ER-Force's simulator.
    ErforceSim = 5,
}

/// A packet of ssl-vision (`SSL_WrapperPacket`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct WrapperPacket {
    /// A camera's detections.
    #[prost(message, optional, tag = "1")]
    pub detection: Option<DetectionFrame>,
    /// The field and the cameras.
    #[prost(message, optional, tag = "2")]
    pub geometry: Option<GeometryData>,
    /// Its sender ([`Source`]).
    #[prost(enumeration = "Source", optional, tag = "3")]
    pub source: Option<i32>,
}

/// A ball seen (`SSL_DetectionBall`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct DetectionBall {
    /// 0 to 1.
    #[prost(float, required, tag = "1")]
    pub confidence: f32,
    /// Its pixels.
    #[prost(uint32, optional, tag = "2")]
    pub area: Option<u32>,
    /// mm.
    #[prost(float, required, tag = "3")]
    pub x: f32,
    /// mm.
    #[prost(float, required, tag = "4")]
    pub y: f32,
    /// Height, mm (simulators may set it).
    #[prost(float, optional, tag = "5")]
    pub z: Option<f32>,
    /// In the image, px.
    #[prost(float, required, tag = "6")]
    pub pixel_x: f32,
    /// In the image, px.
    #[prost(float, required, tag = "7")]
    pub pixel_y: f32,
}

/// A robot seen (`SSL_DetectionRobot`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct DetectionRobot {
    /// 0 to 1.
    #[prost(float, required, tag = "1")]
    pub confidence: f32,
    /// Its number.
    #[prost(uint32, optional, tag = "2")]
    pub robot_id: Option<u32>,
    /// mm.
    #[prost(float, required, tag = "3")]
    pub x: f32,
    /// mm.
    #[prost(float, required, tag = "4")]
    pub y: f32,
    /// rad.
    #[prost(float, optional, tag = "5")]
    pub orientation: Option<f32>,
    /// In the image, px.
    #[prost(float, required, tag = "6")]
    pub pixel_x: f32,
    /// In the image, px.
    #[prost(float, required, tag = "7")]
    pub pixel_y: f32,
    /// mm.
    #[prost(float, optional, tag = "8")]
    pub height: Option<f32>,
}

/// One camera's detections in one frame (`SSL_DetectionFrame`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct DetectionFrame {
    /// The camera's frame count.
    #[prost(uint32, required, tag = "1")]
    pub frame_number: u32,
    /// When the image was taken, Unix s.
    #[prost(double, required, tag = "2")]
    pub t_capture: f64,
    /// When the packet was sent, Unix s.
    #[prost(double, required, tag = "3")]
    pub t_sent: f64,
    /// Which camera.
    #[prost(uint32, required, tag = "4")]
    pub camera_id: u32,
    /// Balls.
    #[prost(message, repeated, tag = "5")]
    pub balls: Vec<DetectionBall>,
    /// Yellow robots.
    #[prost(message, repeated, tag = "6")]
    pub robots_yellow: Vec<DetectionRobot>,
    /// Blue robots.
    #[prost(message, repeated, tag = "7")]
    pub robots_blue: Vec<DetectionRobot>,
    /// When the image was taken, by the camera's clock, s.
    #[prost(double, optional, tag = "8")]
    pub t_capture_camera: Option<f64>,
}

/// What a field line or arc is (`SSL_FieldShapeType`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, prost::Enumeration)]
#[repr(i32)]
pub enum FieldShapeType {
    /// Not set.
    Undefined = 0,
    /// The centre circle.
    CenterCircle = 1,
    /// The touch line at +y.
    TopTouchLine = 2,
    /// The touch line at -y.
    BottomTouchLine = 3,
    /// The goal line at -x.
    LeftGoalLine = 4,
    /// The goal line at +x.
    RightGoalLine = 5,
    /// The halfway line.
    HalfwayLine = 6,
    /// The centre line (along x).
    CenterLine = 7,
    /// The -x defense area's front line.
    LeftPenaltyStretch = 8,
    /// The +x defense area's front line.
    RightPenaltyStretch = 9,
    /// The -x defense area's side at -y.
    LeftFieldLeftPenaltyStretch = 10,
    /// The -x defense area's side at +y.
    LeftFieldRightPenaltyStretch = 11,
    /// The +x defense area's side at -y.
    RightFieldLeftPenaltyStretch = 12,
    /// The +x defense area's side at +y.
    RightFieldRightPenaltyStretch = 13,
}

/// A point, mm (`Vector2f`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct Vector2f {
    /// mm.
    #[prost(float, required, tag = "1")]
    pub x: f32,
    /// mm.
    #[prost(float, required, tag = "2")]
    pub y: f32,
}

/// A straight line on the field (`SSL_FieldLineSegment`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct FieldLineSegment {
    /// Its name.
    #[prost(string, required, tag = "1")]
    pub name: String,
    /// One end.
    #[prost(message, required, tag = "2")]
    pub p1: Vector2f,
    /// The other end.
    #[prost(message, required, tag = "3")]
    pub p2: Vector2f,
    /// mm.
    #[prost(float, required, tag = "4")]
    pub thickness: f32,
    /// What it is ([`FieldShapeType`]).
    #[prost(enumeration = "FieldShapeType", optional, tag = "5")]
    pub r#type: Option<i32>,
}

/// An arc on the field (`SSL_FieldCircularArc`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct FieldCircularArc {
    /// Its name.
    #[prost(string, required, tag = "1")]
    pub name: String,
    /// Its centre.
    #[prost(message, required, tag = "2")]
    pub center: Vector2f,
    /// mm.
    #[prost(float, required, tag = "3")]
    pub radius: f32,
    /// Start, rad counter-clockwise.
    #[prost(float, required, tag = "4")]
    pub a1: f32,
    /// End, rad counter-clockwise.
    #[prost(float, required, tag = "5")]
    pub a2: f32,
    /// mm.
    #[prost(float, required, tag = "6")]
    pub thickness: f32,
    /// What it is ([`FieldShapeType`]).
    #[prost(enumeration = "FieldShapeType", optional, tag = "7")]
    pub r#type: Option<i32>,
}

/// The field's figures (`SSL_GeometryFieldSize`), mm.
#[derive(Clone, PartialEq, prost::Message)]
pub struct GeometryFieldSize {
    /// Goal line to goal line.
    #[prost(int32, required, tag = "1")]
    pub field_length: i32,
    /// Touch line to touch line.
    #[prost(int32, required, tag = "2")]
    pub field_width: i32,
    /// The goal's mouth.
    #[prost(int32, required, tag = "3")]
    pub goal_width: i32,
    /// The goal's depth.
    #[prost(int32, required, tag = "4")]
    pub goal_depth: i32,
    /// Lines to the walls.
    #[prost(int32, required, tag = "5")]
    pub boundary_width: i32,
    /// The lines.
    #[prost(message, repeated, tag = "6")]
    pub field_lines: Vec<FieldLineSegment>,
    /// The arcs.
    #[prost(message, repeated, tag = "7")]
    pub field_arcs: Vec<FieldCircularArc>,
    /// The defense area's depth.
    #[prost(int32, optional, tag = "8")]
    pub penalty_area_depth: Option<i32>,
    /// The defense area's width.
    #[prost(int32, optional, tag = "9")]
    pub penalty_area_width: Option<i32>,
    /// The centre circle's radius.
    #[prost(int32, optional, tag = "10")]
    pub center_circle_radius: Option<i32>,
    /// The lines' thickness.
    #[prost(int32, optional, tag = "11")]
    pub line_thickness: Option<i32>,
    /// Goal centre to penalty mark.
    #[prost(int32, optional, tag = "12")]
    pub goal_center_to_penalty_mark: Option<i32>,
    /// The goal's height.
    #[prost(int32, optional, tag = "13")]
    pub goal_height: Option<i32>,
    /// The ball's radius.
    #[prost(float, optional, tag = "14")]
    pub ball_radius: Option<f32>,
    /// The largest robot's radius.
    #[prost(float, optional, tag = "15")]
    pub max_robot_radius: Option<f32>,
    /// Goal line to the wall.
    #[prost(int32, optional, tag = "16")]
    pub boundary_width_goal_line: Option<i32>,
    /// The substitution area's width.
    #[prost(int32, optional, tag = "17")]
    pub goal_substitution_area_width: Option<i32>,
}

/// An overhead camera's calibration (`SSL_GeometryCameraCalibration`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct GeometryCameraCalibration {
    /// Which camera.
    #[prost(uint32, required, tag = "1")]
    pub camera_id: u32,
    /// px.
    #[prost(float, required, tag = "2")]
    pub focal_length: f32,
    /// px.
    #[prost(float, required, tag = "3")]
    pub principal_point_x: f32,
    /// px.
    #[prost(float, required, tag = "4")]
    pub principal_point_y: f32,
    /// Radial distortion.
    #[prost(float, required, tag = "5")]
    pub distortion: f32,
    /// Rotation quaternion.
    #[prost(float, required, tag = "6")]
    pub q0: f32,
    /// Rotation quaternion.
    #[prost(float, required, tag = "7")]
    pub q1: f32,
    /// Rotation quaternion.
    #[prost(float, required, tag = "8")]
    pub q2: f32,
    /// Rotation quaternion.
    #[prost(float, required, tag = "9")]
    pub q3: f32,
    /// Translation, mm.
    #[prost(float, required, tag = "10")]
    pub tx: f32,
    /// Translation, mm.
    #[prost(float, required, tag = "11")]
    pub ty: f32,
    /// Translation, mm.
    #[prost(float, required, tag = "12")]
    pub tz: f32,
    /// The camera in the world, mm.
    #[prost(float, optional, tag = "13")]
    pub derived_camera_world_tx: Option<f32>,
    /// The camera in the world, mm.
    #[prost(float, optional, tag = "14")]
    pub derived_camera_world_ty: Option<f32>,
    /// The camera in the world, mm.
    #[prost(float, optional, tag = "15")]
    pub derived_camera_world_tz: Option<f32>,
    /// px.
    #[prost(uint32, optional, tag = "16")]
    pub pixel_image_width: Option<u32>,
    /// px.
    #[prost(uint32, optional, tag = "17")]
    pub pixel_image_height: Option<u32>,
}

/// The straight kick's two-phase ball model (`SSL_BallModelStraightTwoPhase`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct BallModelStraightTwoPhase {
    /// Sliding, m/s² (negative).
    #[prost(double, required, tag = "1")]
    pub acc_slide: f64,
    /// Rolling, m/s² (negative).
    #[prost(double, required, tag = "2")]
    pub acc_roll: f64,
    /// Share of the kick speed where rolling starts.
    #[prost(double, required, tag = "3")]
    pub k_switch: f64,
}

/// The chip kick's ball model (`SSL_BallModelChipFixedLoss`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct BallModelChipFixedLoss {
    /// Along the floor, the first hop.
    #[prost(double, required, tag = "1")]
    pub damping_xy_first_hop: f64,
    /// Along the floor, later hops.
    #[prost(double, required, tag = "2")]
    pub damping_xy_other_hops: f64,
    /// Up.
    #[prost(double, required, tag = "3")]
    pub damping_z: f64,
}

/// The ball's models (`SSL_GeometryModels`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct GeometryModels {
    /// Straight kicks.
    #[prost(message, optional, tag = "1")]
    pub straight_two_phase: Option<BallModelStraightTwoPhase>,
    /// Chip kicks.
    #[prost(message, optional, tag = "2")]
    pub chip_fixed_loss: Option<BallModelChipFixedLoss>,
}

/// The field, the cameras and the ball's models (`SSL_GeometryData`).
#[derive(Clone, PartialEq, prost::Message)]
pub struct GeometryData {
    /// The field.
    #[prost(message, required, tag = "1")]
    pub field: GeometryFieldSize,
    /// The cameras.
    #[prost(message, repeated, tag = "2")]
    pub calib: Vec<GeometryCameraCalibration>,
    /// The ball's models.
    #[prost(message, optional, tag = "3")]
    pub models: Option<GeometryModels>,
}
