//! Byte-for-byte round trips of packets encoded by the reference (Python `protobuf`) from the
//! protocols' schemas: each decodes to the values it was made from and encodes back to the
//! same bytes.

use super::referee::{Command, Referee};
use super::sim::{
    MoveCommand, RobotControl, RobotControlResponse, SimulatorCommand, SimulatorResponse, Team,
};
use super::vision::{FieldShapeType, Source, WrapperPacket};
use super::{MAX_DATAGRAM, WireError, decode};
use prost::Message;

fn hex(s: &str) -> Vec<u8> {
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
        .collect()
}

fn round_trip<M: Message + Default>(bytes: &[u8], name: &'static str) -> M {
    let m: M = decode(bytes, name).unwrap();
    assert_eq!(
        m.encode_to_vec(),
        bytes,
        "{name} re-encodes to the same bytes"
    );
    m
}

/// Two robots: one by its local velocity, dribbling; one by the global velocity, kicking at
/// 6.5 m/s and 45 degrees.
#[test]
fn robot_control() {
    let m: RobotControl = round_trip(
        &hex(
            "0a1f08031211120f0d0000803f150000003f1d000080be1d000000002d00007a440a1f080012111a0f0d0000000015000080bf1d000000001d0000d0402500003442",
        ),
        "RobotControl",
    );
    let [a, b] = &m.robot_commands[..] else {
        panic!("{m:?}")
    };
    assert_eq!(a.id, 3);
    let Some(MoveCommand::LocalVelocity(v)) =
        a.move_command.as_ref().and_then(|c| c.command.clone())
    else {
        panic!("{a:?}")
    };
    assert_eq!((v.forward, v.left, v.angular), (1.0, 0.5, -0.25));
    assert_eq!(a.dribbler_speed, Some(1000.0));
    assert!(matches!(
        b.move_command.as_ref().and_then(|c| c.command.clone()),
        Some(MoveCommand::GlobalVelocity(_))
    ));
    assert_eq!((b.kick_speed, b.kick_angle), (Some(6.5), Some(45.0)));
}

/// The ball rolled at 1.5 m/s from the centre; blue robot 1 placed at (-1, 0.5) m, facing -x.
#[test]
fn simulator_command() {
    let m: SimulatorCommand = round_trip(
        &hex(
            "0a3e0a1e0d0000000015000000001d00000000250000c03f2d00000000350000000012170a040801100215000080bf1d0000003f25db0f494040011d0000803f",
        ),
        "SimulatorCommand",
    );
    let c = m.control.unwrap();
    assert_eq!(c.teleport_ball.unwrap().vx, Some(1.5));
    let r = &c.teleport_robot[0];
    assert_eq!((r.id.id, r.id.team), (Some(1), Some(Team::Blue as i32)));
    assert_eq!((r.x, r.y, r.present), (Some(-1.0), Some(0.5), Some(true)));
    assert_eq!(c.simulation_speed, Some(1.0));
    // A simulator-specific realism message travels as an `Any`.
    let m: SimulatorCommand = round_trip(
        &hex(
            "12421a3d0a3b0a28747970652e676f6f676c65617069732e636f6d2f5265616c69736d436f6e6669674572466f726365120f0d3480b73a65cdcc4c3d68c09dd81020a44e",
        ),
        "SimulatorCommand",
    );
    let config = m.config.unwrap();
    assert_eq!(config.vision_port, Some(10020));
    let any = &config.realism_config.unwrap().custom[0];
    assert_eq!(any.type_url, "type.googleapis.com/RealismConfigErForce");
}

/// Errors and feedback, on both ports.
#[test]
fn responses() {
    let m: RobotControlResponse = round_trip(
        &hex(
            "0a1c0a0d56454c4f434954595f54595045120b756e737570706f72746564120408031001120408041000",
        ),
        "RobotControlResponse",
    );
    assert_eq!(m.errors[0].code.as_deref(), Some("VELOCITY_TYPE"));
    assert_eq!(m.feedback.len(), 2);
    assert_eq!(
        (m.feedback[0].id, m.feedback[0].dribbler_ball_contact),
        (3, Some(true))
    );
    let m: SimulatorResponse = round_trip(
        &hex("0a1d0a1b475253494d5f554e535550504f525445445f524f4c4c5f42414c4c"),
        "SimulatorResponse",
    );
    assert_eq!(
        m.errors[0].code.as_deref(),
        Some("GRSIM_UNSUPPORTED_ROLL_BALL")
    );
}

/// A detection frame with a ball and a robot of each team, and a geometry packet.
#[test]
fn vision_packets() {
    let m: WrapperPacket = round_trip(
        &hex(
            "0a8101082a1100001040fc54d9411900002040fc54d94120012a200d6666663f10781d00007a44250000fac32d00000000350000a0433d0000704332200d0000403f10001d0000000025000000002d00000000350000803f3d000000403a250d0000803f10051d0000fac4250080bb442ddb0fc93f350000c8423d0000484245000016431805",
        ),
        "SSL_WrapperPacket",
    );
    assert_eq!(m.source, Some(Source::ErforceSim as i32));
    let d = m.detection.unwrap();
    assert_eq!(
        (d.frame_number, d.camera_id, d.t_capture),
        (42, 1, 1_700_000_000.25)
    );
    assert_eq!((d.balls[0].x, d.balls[0].y), (1000.0, -500.0));
    assert_eq!(d.robots_blue[0].robot_id, Some(5));
    assert_eq!(d.robots_blue[0].height, Some(150.0));
    let m: WrapperPacket = round_trip(
        &hex(
            "12d7010a7b08e05d10a84618880e20b40128ac02322d0a0c546f70546f7563684c696e65120a0d0080bbc51500a08c451a0a0d0080bb451500a08c45250000204128023a300a0c43656e746572436972636c65120a0d0000000015000000001d0000fa4325000000002ddb0fc9403500002041380140880e48901c750000ac4112390800150000fa431d0000c34325000091432d00000000353333333f3d333333bf45000000004d0000000055000000005d00409c446500c05a451a1d0a1b0900000000000008c011a4703d0ad7a3d0bf1914ae47e17a14e63f",
        ),
        "SSL_WrapperPacket",
    );
    let g = m.geometry.unwrap();
    assert_eq!((g.field.field_length, g.field.field_width), (12000, 9000));
    assert_eq!(
        g.field.field_lines[0].r#type,
        Some(FieldShapeType::TopTouchLine as i32)
    );
    assert_eq!(g.field.ball_radius, Some(21.5));
    assert_eq!(g.calib[0].ty, 1250.0);
    assert_eq!(g.models.unwrap().straight_two_phase.unwrap().k_switch, 0.69);
}

/// The referee's packet, a packed repeated field and a zig-zag one among its fields.
#[test]
fn referee() {
    let m: Referee = round_trip(
        &hex(
            "08c0c480c1c1c48203100118bf8db70120102807308080f9c0c1c482033a290a0959656c6c6f77204643100218002208809c9c398087a70e280130043880c6868f0140006001680a42190a07426c756520464310011800280130043880c6868f0140004a0a0d0080bbc41500803b4450016008788087a70e920103616263980101a20109706c6163656d656e74",
        ),
        "Referee",
    );
    assert_eq!(m.command, Command::BallPlacementYellow as i32);
    assert_eq!(m.stage_time_left, Some(-1_500_000));
    assert_eq!(m.yellow.yellow_card_times, [120_000_000, 30_000_000]);
    assert_eq!((m.yellow.score, m.blue.score), (2, 1));
    assert_eq!(m.next_command, Some(Command::DirectFreeYellow as i32));
}

#[test]
fn garbage_and_floods_are_refused_with_the_reason() {
    let e = decode::<RobotControl>(&[0x0a, 0xff, 0xff], "RobotControl").unwrap_err();
    assert!(
        matches!(
            e,
            WireError::Malformed {
                message: "RobotControl",
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().starts_with("not a RobotControl: "), "{e}");
    let big = vec![0u8; MAX_DATAGRAM + 1];
    assert_eq!(
        decode::<RobotControl>(&big, "RobotControl").unwrap_err(),
        WireError::TooLong {
            len: MAX_DATAGRAM + 1
        }
    );
}
