"""The RoboCup Small-Size League's wire formats, and a client of ``omniloop ssl`` (``pip install
omniloop[ssl]``, which brings ``protobuf``)::

    from omniloop import ssl

    vision, referee = ssl.VisionReceiver(), ssl.RefereeReceiver()   # free ports of 127.0.0.1
    with ssl.serve("scenarios/ssl_match.toml", lockstep=True, extra_args=["--no-cameras"],
                   vision=vision.address, referee=referee.address) as s, s.client() as client:
        client.teleport_ball(0.5, 0.0)
        client.command("yellow", [ssl.local_velocity(0, 0.5, 0.0)])   # held until the step
        answer = client.sync("blue", 0.01, [ssl.global_velocity(3, 1.0, 0.0)])
        for frame in answer.detection:                               # ssl-vision's frames, mm
            print(frame.camera_id, [(r.robot_id, r.x, r.y) for r in frame.robots_blue])
        print(referee.receive(1.0).blue.score)                       # the referee's packet

The messages are the league's, proto2 without a package, built here from their field numbers
at import time (a private descriptor pool, so that they live beside another copy of the same
messages, such as ssl-vision's generated modules): the simulation protocol's (``RobotControl``,
``RobotCommand`` with its three ``RobotMoveCommand``\\ s, ``RobotControlResponse`` with
``RobotFeedback`` and ``SimulatorError``, ``SimulatorCommand`` with ``SimulatorControl``
(``TeleportBall``, ``TeleportRobot``) and ``SimulatorConfig``, ``SimulatorResponse``), the
draft synchronous pair ``SimulationSyncRequest``/``SimulationSyncResponse``, ssl-vision's
(``SSL_WrapperPacket``, ``SSL_DetectionFrame``, ``SSL_DetectionBall``, ``SSL_DetectionRobot``,
``SSL_GeometryData``, ``SSL_GeometryFieldSize``, ...) and the game controller's ``Referee``
(``Referee.TeamInfo``, the ``Stage`` and ``Command`` enums). Each is a ``protobuf`` message
class: ``SerializeToString()``, ``FromString(bytes)``. They are typed ``Any`` (``protobuf``
makes them at run time); the enums are also Python ``IntEnum``\\ s here (``Team``, ``Stage``,
``Command``).

Units are the protocols': metres, m/s, radians and rpm on the simulation protocol (degrees for a
kick's angle), millimetres in vision's detections and geometry, microseconds in the referee's
packets. Blue defends the goal at -x: a goal into it is yellow's.

- ``serve(scenario, lockstep=..., extra_args=..., binary=None)``: starts ``omniloop ssl`` on
  free ports of 127.0.0.1 and gives their addresses (``Served``); the binary is ``binary``,
  else ``$OMNILOOP_BIN``, else ``omniloop`` on the ``PATH``, else the repository's
  ``target/debug/omniloop``.
- ``SslClient(control, blue, yellow)``: ``teleport_ball``, ``teleport_robot``,
  ``simulator_command``, ``referee_command`` (a game controller's command), ``command`` (a
  team's ``RobotCommand``\\ s, answered with its feedback and errors) and, in lockstep,
  ``sync``. Each waits for the answer and raises ``SslTimeout`` (a ``TimeoutError``) after
  ``timeout_s``.
- ``local_velocity``, ``global_velocity``, ``wheel_velocity``: a ``RobotCommand``, with a kick
  and the dribbler as keywords.
- ``VisionReceiver(addr)``: ssl-vision's packets, merged into ``VisionState`` (each robot and
  the ball as the latest frames saw them); ``RefereeReceiver(addr)``: the referee's packets and
  the score. An address is ``"HOST:PORT"`` or ``(host, port)``; port 0 takes a free one, and a
  multicast group is joined.
"""

from __future__ import annotations

import contextlib
import enum
import ipaddress
import json
import math
import os
import shutil
import signal
import socket
import struct
import subprocess
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Dict, Iterator, List, Optional, Sequence, Tuple, Type, TypeVar, Union

from google.protobuf import any_pb2, descriptor_pb2, descriptor_pool, message_factory

__all__ = [
    "Address",
    "AddressLike",
    "Command",
    "FieldShapeType",
    "HullColor",
    "MatchType",
    "MoveGlobalVelocity",
    "MoveLocalVelocity",
    "MoveWheelVelocity",
    "POOL",
    "RealismConfig",
    "Referee",
    "RefereePoint",
    "RefereeReceiver",
    "RobotCommand",
    "RobotControl",
    "RobotControlResponse",
    "RobotFeedback",
    "RobotId",
    "RobotLimits",
    "RobotMoveCommand",
    "RobotSeen",
    "RobotSpecs",
    "RobotWheelAngles",
    "SSL_BallModelChipFixedLoss",
    "SSL_BallModelStraightTwoPhase",
    "SSL_DetectionBall",
    "SSL_DetectionFrame",
    "SSL_DetectionRobot",
    "SSL_FieldCircularArc",
    "SSL_FieldLineSegment",
    "SSL_GeometryCameraCalibration",
    "SSL_GeometryData",
    "SSL_GeometryFieldSize",
    "SSL_GeometryModels",
    "SSL_WrapperPacket",
    "Served",
    "SimulationSyncRequest",
    "SimulationSyncResponse",
    "SimulatorCommand",
    "SimulatorConfig",
    "SimulatorControl",
    "SimulatorError",
    "SimulatorResponse",
    "SslClient",
    "SslTimeout",
    "Stage",
    "Team",
    "TeamInfo",
    "TeamLike",
    "TeleportBall",
    "TeleportRobot",
    "Vector2f",
    "VisionReceiver",
    "VisionState",
    "address_text",
    "binary_path",
    "error_codes",
    "global_velocity",
    "local_velocity",
    "message_class",
    "parse_address",
    "serve",
    "team_of",
    "wheel_velocity",
]

# --------------------------------------------------------------------------------------------
# The enums, as Python sees them and as the descriptors declare them.


class Team(enum.IntEnum):
    """A team's colour (the game controller's ``Team``)."""

    UNKNOWN = 0
    YELLOW = 1
    BLUE = 2


class Stage(enum.IntEnum):
    """The game's stage (``Referee.Stage``)."""

    NORMAL_FIRST_HALF_PRE = 0
    NORMAL_FIRST_HALF = 1
    NORMAL_HALF_TIME = 2
    NORMAL_SECOND_HALF_PRE = 3
    NORMAL_SECOND_HALF = 4
    EXTRA_TIME_BREAK = 5
    EXTRA_FIRST_HALF_PRE = 6
    EXTRA_FIRST_HALF = 7
    EXTRA_HALF_TIME = 8
    EXTRA_SECOND_HALF_PRE = 9
    EXTRA_SECOND_HALF = 10
    PENALTY_SHOOTOUT_BREAK = 11
    PENALTY_SHOOTOUT = 12
    POST_GAME = 13


class Command(enum.IntEnum):
    """The referee's command (``Referee.Command``)."""

    HALT = 0
    STOP = 1
    NORMAL_START = 2
    FORCE_START = 3
    PREPARE_KICKOFF_YELLOW = 4
    PREPARE_KICKOFF_BLUE = 5
    PREPARE_PENALTY_YELLOW = 6
    PREPARE_PENALTY_BLUE = 7
    DIRECT_FREE_YELLOW = 8
    DIRECT_FREE_BLUE = 9
    INDIRECT_FREE_YELLOW = 10
    INDIRECT_FREE_BLUE = 11
    TIMEOUT_YELLOW = 12
    TIMEOUT_BLUE = 13
    GOAL_YELLOW = 14
    GOAL_BLUE = 15
    BALL_PLACEMENT_YELLOW = 16
    BALL_PLACEMENT_BLUE = 17


class MatchType(enum.IntEnum):
    """The kind of match (the referee's ``MatchType``)."""

    UNKNOWN_MATCH = 0
    GROUP_PHASE = 1
    ELIMINATION_PHASE = 2
    FRIENDLY = 3


class HullColor(enum.IntEnum):
    """A team's robots' hull colour (the referee's ``TeamInfo.hull_color``)."""

    HULL_COLOR_UNKNOWN = 0
    DARK = 1
    LIGHT = 2


class FieldShapeType(enum.IntEnum):
    """What a field line or arc is (ssl-vision's ``SSL_FieldShapeType``)."""

    Undefined = 0
    CenterCircle = 1
    TopTouchLine = 2
    BottomTouchLine = 3
    LeftGoalLine = 4
    RightGoalLine = 5
    HalfwayLine = 6
    CenterLine = 7
    LeftPenaltyStretch = 8
    RightPenaltyStretch = 9
    LeftFieldLeftPenaltyStretch = 10
    LeftFieldRightPenaltyStretch = 11
    RightFieldLeftPenaltyStretch = 12
    RightFieldRightPenaltyStretch = 13


# --------------------------------------------------------------------------------------------
# The descriptors: each message as (label, type, name, number[, default]) rows. A type starting
# with "." names a message or an enum of this file (or google.protobuf.Any).

_FDP = descriptor_pb2.FieldDescriptorProto
_SCALARS = {
    "double": _FDP.TYPE_DOUBLE,
    "float": _FDP.TYPE_FLOAT,
    "int32": _FDP.TYPE_INT32,
    "int64": _FDP.TYPE_INT64,
    "uint32": _FDP.TYPE_UINT32,
    "uint64": _FDP.TYPE_UINT64,
    "sint64": _FDP.TYPE_SINT64,
    "bool": _FDP.TYPE_BOOL,
    "string": _FDP.TYPE_STRING,
    "bytes": _FDP.TYPE_BYTES,
}
_LABELS = {
    "optional": _FDP.LABEL_OPTIONAL,
    "required": _FDP.LABEL_REQUIRED,
    "repeated": _FDP.LABEL_REPEATED,
}
# The enums' full names and their values.
_ENUMS: Dict[str, Type[enum.IntEnum]] = {
    ".Team": Team,
    ".MatchType": MatchType,
    ".HullColor": HullColor,
    ".SSL_FieldShapeType": FieldShapeType,
    ".Referee.Stage": Stage,
    ".Referee.Command": Command,
}

# A field: label, type, name, number, and optionally its default (as text) or, for a oneof's
# member, "oneof:INDEX", or "packed".
_Row = Tuple[Any, ...]


@dataclass
class _Msg:
    name: str
    rows: List[_Row]
    nested: List["_Msg"] = field(default_factory=list)
    enums: List[str] = field(default_factory=list)
    oneofs: List[str] = field(default_factory=list)


def _enum_proto(full_name: str) -> Any:
    e = descriptor_pb2.EnumDescriptorProto(name=full_name.rsplit(".", 1)[-1])
    for member in _ENUMS[full_name]:
        e.value.add(name=member.name, number=int(member.value))
    return e


def _message_proto(m: _Msg) -> Any:
    d = descriptor_pb2.DescriptorProto(name=m.name)
    for o in m.oneofs:
        d.oneof_decl.add(name=o)
    for label, type_, name, number, *extra in m.rows:
        f = d.field.add(name=name, number=number, label=_LABELS[label])
        if type_ in _SCALARS:
            f.type = _SCALARS[type_]
        else:
            f.type = _FDP.TYPE_ENUM if type_ in _ENUMS else _FDP.TYPE_MESSAGE
            f.type_name = type_
        for x in extra:
            if x == "packed":
                f.options.packed = True
            elif isinstance(x, str) and x.startswith("oneof:"):
                f.oneof_index = int(x.split(":", 1)[1])
            else:
                f.default_value = str(x)
    for n in m.nested:
        d.nested_type.append(_message_proto(n))
    for e in m.enums:
        d.enum_type.append(_enum_proto(e))
    return d


def _o(type_: str, name: str, number: int, *extra: Any) -> _Row:
    return ("optional", type_, name, number, *extra)


def _r(type_: str, name: str, number: int, *extra: Any) -> _Row:
    return ("required", type_, name, number, *extra)


def _rep(type_: str, name: str, number: int, *extra: Any) -> _Row:
    return ("repeated", type_, name, number, *extra)


_ANY = ".google.protobuf.Any"

# The simulation protocol (github.com/RoboCup-SSL/ssl-simulation-protocol).
_SIMULATION = [
    _Msg("RobotId", [_o("uint32", "id", 1), _o(".Team", "team", 2)]),
    _Msg(
        "MoveWheelVelocity",
        [
            _r("float", "front_right", 1),
            _r("float", "back_right", 2),
            _r("float", "back_left", 3),
            _r("float", "front_left", 4),
        ],
    ),
    _Msg(
        "MoveLocalVelocity",
        [_r("float", "forward", 1), _r("float", "left", 2), _r("float", "angular", 3)],
    ),
    _Msg(
        "MoveGlobalVelocity",
        [_r("float", "x", 1), _r("float", "y", 2), _r("float", "angular", 3)],
    ),
    _Msg(
        "RobotMoveCommand",
        [
            _o(".MoveWheelVelocity", "wheel_velocity", 1, "oneof:0"),
            _o(".MoveLocalVelocity", "local_velocity", 2, "oneof:0"),
            _o(".MoveGlobalVelocity", "global_velocity", 3, "oneof:0"),
        ],
        oneofs=["command"],
    ),
    _Msg(
        "RobotCommand",
        [
            _r("uint32", "id", 1),
            _o(".RobotMoveCommand", "move_command", 2),
            _o("float", "kick_speed", 3),
            _o("float", "kick_angle", 4, "0"),
            _o("float", "dribbler_speed", 5),
        ],
    ),
    _Msg("RobotControl", [_rep(".RobotCommand", "robot_commands", 1)]),
    _Msg(
        "RobotFeedback",
        [_r("uint32", "id", 1), _o("bool", "dribbler_ball_contact", 2), _o(_ANY, "custom", 3)],
    ),
    _Msg("SimulatorError", [_o("string", "code", 1), _o("string", "message", 2)]),
    _Msg(
        "RobotControlResponse",
        [_rep(".SimulatorError", "errors", 1), _rep(".RobotFeedback", "feedback", 2)],
    ),
    _Msg(
        "TeleportBall",
        [
            _o("float", "x", 1),
            _o("float", "y", 2),
            _o("float", "z", 3),
            _o("float", "vx", 4),
            _o("float", "vy", 5),
            _o("float", "vz", 6),
            _o("bool", "teleport_safely", 7, "false"),
            _o("bool", "roll", 8, "false"),
            _o("bool", "by_force", 9, "false"),
        ],
    ),
    _Msg(
        "TeleportRobot",
        [
            _r(".RobotId", "id", 1),
            _o("float", "x", 2),
            _o("float", "y", 3),
            _o("float", "orientation", 4),
            _o("float", "v_x", 5, "0"),
            _o("float", "v_y", 6, "0"),
            _o("float", "v_angular", 7, "0"),
            _o("bool", "present", 8),
            _o("bool", "by_force", 9, "false"),
        ],
    ),
    _Msg(
        "SimulatorControl",
        [
            _o(".TeleportBall", "teleport_ball", 1),
            _rep(".TeleportRobot", "teleport_robot", 2),
            _o("float", "simulation_speed", 3),
        ],
    ),
    _Msg(
        "RobotLimits",
        [
            _o("float", "acc_speedup_absolute_max", 1),
            _o("float", "acc_speedup_angular_max", 2),
            _o("float", "acc_brake_absolute_max", 3),
            _o("float", "acc_brake_angular_max", 4),
            _o("float", "vel_absolute_max", 5),
            _o("float", "vel_angular_max", 6),
        ],
    ),
    _Msg(
        "RobotWheelAngles",
        [
            _r("float", "front_right", 1),
            _r("float", "back_right", 2),
            _r("float", "back_left", 3),
            _r("float", "front_left", 4),
        ],
    ),
    _Msg(
        "RobotSpecs",
        [
            _r(".RobotId", "id", 1),
            _o("float", "radius", 2, "0.09"),
            _o("float", "height", 3, "0.15"),
            _o("float", "mass", 4),
            _o("float", "max_linear_kick_speed", 7),
            _o("float", "max_chip_kick_speed", 8),
            _o("float", "center_to_dribbler", 9),
            _o(".RobotLimits", "limits", 10),
            _o(".RobotWheelAngles", "wheel_angles", 13),
            _rep(_ANY, "custom", 14),
        ],
    ),
    _Msg("RealismConfig", [_rep(_ANY, "custom", 1)]),
    _Msg(
        "SimulatorConfig",
        [
            _o(".SSL_GeometryData", "geometry", 1),
            _rep(".RobotSpecs", "robot_specs", 2),
            _o(".RealismConfig", "realism_config", 3),
            _o("uint32", "vision_port", 4),
        ],
    ),
    _Msg(
        "SimulatorCommand",
        [_o(".SimulatorControl", "control", 1), _o(".SimulatorConfig", "config", 2)],
    ),
    _Msg("SimulatorResponse", [_rep(".SimulatorError", "errors", 1)]),
    _Msg(
        "SimulationSyncRequest",
        [
            _o("float", "sim_step", 1),
            _o(".SimulatorCommand", "simulator_command", 2),
            _o(".RobotControl", "robot_control", 3),
        ],
    ),
    _Msg(
        "SimulationSyncResponse",
        [
            _rep(".SSL_DetectionFrame", "detection", 1),
            _o(".RobotControlResponse", "robot_control_response", 2),
        ],
    ),
]

# ssl-vision's packets (github.com/RoboCup-SSL/ssl-vision): millimetres.
_VISION = [
    _Msg(
        "SSL_DetectionBall",
        [
            _r("float", "confidence", 1),
            _o("uint32", "area", 2),
            _r("float", "x", 3),
            _r("float", "y", 4),
            _o("float", "z", 5),
            _r("float", "pixel_x", 6),
            _r("float", "pixel_y", 7),
        ],
    ),
    _Msg(
        "SSL_DetectionRobot",
        [
            _r("float", "confidence", 1),
            _o("uint32", "robot_id", 2),
            _r("float", "x", 3),
            _r("float", "y", 4),
            _o("float", "orientation", 5),
            _r("float", "pixel_x", 6),
            _r("float", "pixel_y", 7),
            _o("float", "height", 8),
        ],
    ),
    _Msg(
        "SSL_DetectionFrame",
        [
            _r("uint32", "frame_number", 1),
            _r("double", "t_capture", 2),
            _r("double", "t_sent", 3),
            _r("uint32", "camera_id", 4),
            _rep(".SSL_DetectionBall", "balls", 5),
            _rep(".SSL_DetectionRobot", "robots_yellow", 6),
            _rep(".SSL_DetectionRobot", "robots_blue", 7),
            _o("double", "t_capture_camera", 8),
        ],
    ),
    _Msg("Vector2f", [_r("float", "x", 1), _r("float", "y", 2)]),
    _Msg(
        "SSL_FieldLineSegment",
        [
            _r("string", "name", 1),
            _r(".Vector2f", "p1", 2),
            _r(".Vector2f", "p2", 3),
            _r("float", "thickness", 4),
            _o(".SSL_FieldShapeType", "type", 5),
        ],
    ),
    _Msg(
        "SSL_FieldCircularArc",
        [
            _r("string", "name", 1),
            _r(".Vector2f", "center", 2),
            _r("float", "radius", 3),
            _r("float", "a1", 4),
            _r("float", "a2", 5),
            _r("float", "thickness", 6),
            _o(".SSL_FieldShapeType", "type", 7),
        ],
    ),
    _Msg(
        "SSL_GeometryFieldSize",
        [
            _r("int32", "field_length", 1),
            _r("int32", "field_width", 2),
            _r("int32", "goal_width", 3),
            _r("int32", "goal_depth", 4),
            _r("int32", "boundary_width", 5),
            _rep(".SSL_FieldLineSegment", "field_lines", 6),
            _rep(".SSL_FieldCircularArc", "field_arcs", 7),
            _o("int32", "penalty_area_depth", 8),
            _o("int32", "penalty_area_width", 9),
            _o("int32", "center_circle_radius", 10),
            _o("int32", "line_thickness", 11),
            _o("int32", "goal_center_to_penalty_mark", 12),
            _o("int32", "goal_height", 13),
            _o("float", "ball_radius", 14),
            _o("float", "max_robot_radius", 15),
            _o("int32", "boundary_width_goal_line", 16),
            _o("int32", "goal_substitution_area_width", 17),
        ],
    ),
    _Msg(
        "SSL_GeometryCameraCalibration",
        [
            _r("uint32", "camera_id", 1),
            _r("float", "focal_length", 2),
            _r("float", "principal_point_x", 3),
            _r("float", "principal_point_y", 4),
            _r("float", "distortion", 5),
            _r("float", "q0", 6),
            _r("float", "q1", 7),
            _r("float", "q2", 8),
            _r("float", "q3", 9),
            _r("float", "tx", 10),
            _r("float", "ty", 11),
            _r("float", "tz", 12),
            _o("float", "derived_camera_world_tx", 13),
            _o("float", "derived_camera_world_ty", 14),
            _o("float", "derived_camera_world_tz", 15),
            _o("uint32", "pixel_image_width", 16),
            _o("uint32", "pixel_image_height", 17),
        ],
    ),
    _Msg(
        "SSL_BallModelStraightTwoPhase",
        [_r("double", "acc_slide", 1), _r("double", "acc_roll", 2), _r("double", "k_switch", 3)],
    ),
    _Msg(
        "SSL_BallModelChipFixedLoss",
        [
            _r("double", "damping_xy_first_hop", 1),
            _r("double", "damping_xy_other_hops", 2),
            _r("double", "damping_z", 3),
        ],
    ),
    _Msg(
        "SSL_GeometryModels",
        [
            _o(".SSL_BallModelStraightTwoPhase", "straight_two_phase", 1),
            _o(".SSL_BallModelChipFixedLoss", "chip_fixed_loss", 2),
        ],
    ),
    _Msg(
        "SSL_GeometryData",
        [
            _r(".SSL_GeometryFieldSize", "field", 1),
            _rep(".SSL_GeometryCameraCalibration", "calib", 2),
            _o(".SSL_GeometryModels", "models", 3),
        ],
    ),
    _Msg(
        "SSL_WrapperPacket",
        [_o(".SSL_DetectionFrame", "detection", 1), _o(".SSL_GeometryData", "geometry", 2)],
    ),
]

# The game controller's referee packet (github.com/RoboCup-SSL/ssl-game-controller); its game
# events (fields 16 and 17) are left out: a parser keeps them as unknown fields.
_REFEREE = [
    _Msg(
        "Referee",
        [
            _r("uint64", "packet_timestamp", 1),
            _r(".Referee.Stage", "stage", 2),
            _o("sint64", "stage_time_left", 3),
            _r(".Referee.Command", "command", 4),
            _r("uint32", "command_counter", 5),
            _r("uint64", "command_timestamp", 6),
            _r(".Referee.TeamInfo", "yellow", 7),
            _r(".Referee.TeamInfo", "blue", 8),
            _o(".Referee.Point", "designated_position", 9),
            _o("bool", "blue_team_on_positive_half", 10),
            _o(".Referee.Command", "next_command", 12),
            _o("int64", "current_action_time_remaining", 15),
            _o("string", "source_identifier", 18),
            _o(".MatchType", "match_type", 19, "UNKNOWN_MATCH"),
            _o("string", "status_message", 20),
        ],
        nested=[
            _Msg(
                "TeamInfo",
                [
                    _r("string", "name", 1),
                    _r("uint32", "score", 2),
                    _r("uint32", "red_cards", 3),
                    _rep("uint32", "yellow_card_times", 4, "packed"),
                    _r("uint32", "yellow_cards", 5),
                    _r("uint32", "timeouts", 6),
                    _r("uint32", "timeout_time", 7),
                    _r("uint32", "goalkeeper", 8),
                    _o("uint32", "foul_counter", 9),
                    _o("uint32", "ball_placement_failures", 10),
                    _o("bool", "can_place_ball", 12),
                    _o("uint32", "max_allowed_bots", 13),
                    _o("bool", "bot_substitution_intent", 14),
                    _o("bool", "ball_placement_failures_reached", 15),
                    _o("bool", "bot_substitution_allowed", 16),
                    _o("uint32", "bot_substitutions_left", 17),
                    _o("uint32", "bot_substitution_time_left", 18),
                    _o(".HullColor", "hull_color", 19),
                ],
            ),
            _Msg("Point", [_r("float", "x", 1), _r("float", "y", 2)]),
        ],
        enums=[".Referee.Stage", ".Referee.Command"],
    ),
]


def _build_pool() -> Any:
    """A descriptor pool of its own holding google.protobuf.Any and the league's messages."""
    pool = descriptor_pool.DescriptorPool()
    any_file = descriptor_pb2.FileDescriptorProto()
    any_pb2.DESCRIPTOR.CopyToProto(any_file)
    pool.AddSerializedFile(any_file.SerializeToString())
    f = descriptor_pb2.FileDescriptorProto(
        name="omniloop/ssl_protocols.proto", syntax="proto2", dependency=[any_file.name]
    )
    for name in (".Team", ".MatchType", ".HullColor", ".SSL_FieldShapeType"):
        f.enum_type.append(_enum_proto(name))
    for m in _SIMULATION + _VISION + _REFEREE:
        f.message_type.append(_message_proto(m))
    pool.AddSerializedFile(f.SerializeToString())
    return pool


POOL: Any = _build_pool()
"""The descriptor pool of the messages below (not protobuf's default pool)."""


def message_class(full_name: str) -> Any:
    """The message class of ``full_name`` in ``POOL`` (e.g. ``"Referee.TeamInfo"``): with
    ``protobuf`` 4 and later ``message_factory.GetMessageClass``, with 3.20
    ``MessageFactory.GetPrototype``."""
    descriptor = POOL.FindMessageTypeByName(full_name)
    get = getattr(message_factory, "GetMessageClass", None)
    if get is not None:
        return get(descriptor)
    return message_factory.MessageFactory(POOL).GetPrototype(descriptor)


# The simulation protocol's messages.
RobotId: Any = message_class("RobotId")
MoveWheelVelocity: Any = message_class("MoveWheelVelocity")
MoveLocalVelocity: Any = message_class("MoveLocalVelocity")
MoveGlobalVelocity: Any = message_class("MoveGlobalVelocity")
RobotMoveCommand: Any = message_class("RobotMoveCommand")
RobotCommand: Any = message_class("RobotCommand")
RobotControl: Any = message_class("RobotControl")
RobotFeedback: Any = message_class("RobotFeedback")
SimulatorError: Any = message_class("SimulatorError")
RobotControlResponse: Any = message_class("RobotControlResponse")
TeleportBall: Any = message_class("TeleportBall")
TeleportRobot: Any = message_class("TeleportRobot")
SimulatorControl: Any = message_class("SimulatorControl")
RobotLimits: Any = message_class("RobotLimits")
RobotWheelAngles: Any = message_class("RobotWheelAngles")
RobotSpecs: Any = message_class("RobotSpecs")
RealismConfig: Any = message_class("RealismConfig")
SimulatorConfig: Any = message_class("SimulatorConfig")
SimulatorCommand: Any = message_class("SimulatorCommand")
SimulatorResponse: Any = message_class("SimulatorResponse")
SimulationSyncRequest: Any = message_class("SimulationSyncRequest")
SimulationSyncResponse: Any = message_class("SimulationSyncResponse")
# ssl-vision's.
SSL_DetectionBall: Any = message_class("SSL_DetectionBall")
SSL_DetectionRobot: Any = message_class("SSL_DetectionRobot")
SSL_DetectionFrame: Any = message_class("SSL_DetectionFrame")
Vector2f: Any = message_class("Vector2f")
SSL_FieldLineSegment: Any = message_class("SSL_FieldLineSegment")
SSL_FieldCircularArc: Any = message_class("SSL_FieldCircularArc")
SSL_GeometryFieldSize: Any = message_class("SSL_GeometryFieldSize")
SSL_GeometryCameraCalibration: Any = message_class("SSL_GeometryCameraCalibration")
SSL_BallModelStraightTwoPhase: Any = message_class("SSL_BallModelStraightTwoPhase")
SSL_BallModelChipFixedLoss: Any = message_class("SSL_BallModelChipFixedLoss")
SSL_GeometryModels: Any = message_class("SSL_GeometryModels")
SSL_GeometryData: Any = message_class("SSL_GeometryData")
SSL_WrapperPacket: Any = message_class("SSL_WrapperPacket")
# The game controller's.
Referee: Any = message_class("Referee")
TeamInfo: Any = message_class("Referee.TeamInfo")
RefereePoint: Any = message_class("Referee.Point")

# --------------------------------------------------------------------------------------------
# Robot commands.

TeamLike = Union[str, int]
"""A team: ``"blue"``, ``"yellow"``, or ``Team.BLUE``/``Team.YELLOW``."""


def team_of(team: TeamLike) -> Team:
    """``team`` as a ``Team`` (``"blue"``, ``"yellow"``, either case, or the enum's value);
    ``ValueError`` for anything else."""
    if isinstance(team, str):
        try:
            t = Team[team.upper()]
        except KeyError:
            raise ValueError(f"team {team!r}: 'blue' or 'yellow'") from None
    else:
        t = Team(team)
    if t == Team.UNKNOWN:
        raise ValueError("team UNKNOWN: 'blue' or 'yellow'")
    return t


def _with_extras(
    c: Any,
    kick_speed: Optional[float],
    kick_angle: Optional[float],
    dribbler_speed: Optional[float],
) -> Any:
    if kick_speed is not None:
        c.kick_speed = kick_speed
    if kick_angle is not None:
        c.kick_angle = kick_angle
    if dribbler_speed is not None:
        c.dribbler_speed = dribbler_speed
    return c


def local_velocity(
    id: int,
    forward: float,
    left: float,
    angular: float = 0.0,
    *,
    kick_speed: Optional[float] = None,
    kick_angle: Optional[float] = None,
    dribbler_speed: Optional[float] = None,
) -> Any:
    """A ``RobotCommand`` for robot ``id``: a velocity in its own frame, ``forward`` (toward
    the dribbler) and ``left`` in m/s, ``angular`` in rad/s counter-clockwise. ``kick_speed``
    (m/s, 0: none) arms the kicker until the ball touches the dribbler, at ``kick_angle``
    degrees above the floor; ``dribbler_speed`` in rpm."""
    c = RobotCommand(id=id)
    c.move_command.local_velocity.forward = forward
    c.move_command.local_velocity.left = left
    c.move_command.local_velocity.angular = angular
    return _with_extras(c, kick_speed, kick_angle, dribbler_speed)


def global_velocity(
    id: int,
    x: float,
    y: float,
    angular: float = 0.0,
    *,
    kick_speed: Optional[float] = None,
    kick_angle: Optional[float] = None,
    dribbler_speed: Optional[float] = None,
) -> Any:
    """A ``RobotCommand`` for robot ``id``: a velocity in the field's frame, ``x`` and ``y`` in
    m/s, ``angular`` in rad/s; the kick and dribbler as in ``local_velocity``."""
    c = RobotCommand(id=id)
    c.move_command.global_velocity.x = x
    c.move_command.global_velocity.y = y
    c.move_command.global_velocity.angular = angular
    return _with_extras(c, kick_speed, kick_angle, dribbler_speed)


def wheel_velocity(
    id: int,
    front_right: float,
    back_right: float,
    back_left: float,
    front_left: float,
    *,
    kick_speed: Optional[float] = None,
    kick_angle: Optional[float] = None,
    dribbler_speed: Optional[float] = None,
) -> Any:
    """A ``RobotCommand`` for robot ``id``: each wheel's speed at its rim, m/s (positive on
    all four turns the robot counter-clockwise); the kick and dribbler as in
    ``local_velocity``."""
    c = RobotCommand(id=id)
    w = c.move_command.wheel_velocity
    w.front_right, w.back_right, w.back_left, w.front_left = (
        front_right,
        back_right,
        back_left,
        front_left,
    )
    return _with_extras(c, kick_speed, kick_angle, dribbler_speed)


def error_codes(response: Any) -> List[str]:
    """The ``code`` of each ``SimulatorError`` of a response (``SimulatorResponse``,
    ``RobotControlResponse`` or ``SimulationSyncResponse``)."""
    if response.DESCRIPTOR.name == "SimulationSyncResponse":
        response = response.robot_control_response
    return [e.code for e in response.errors]


# --------------------------------------------------------------------------------------------
# Addresses and sockets.

Address = Tuple[str, int]
"""A host and a UDP port."""

AddressLike = Union[str, Tuple[str, int]]
"""``"HOST:PORT"`` (``"[::1]:PORT"`` for IPv6) or ``(host, port)``."""


def parse_address(a: AddressLike) -> Address:
    """``a`` as ``(host, port)``; ``ValueError`` when it is not ``HOST:PORT``."""
    if isinstance(a, tuple):
        return (str(a[0]), int(a[1]))
    host, sep, port = a.rpartition(":")
    if not sep or not port.isdigit():
        raise ValueError(f"{a!r} is not HOST:PORT")
    return (host.strip("[]") or "0.0.0.0", int(port))


def address_text(a: AddressLike) -> str:
    """``a`` as ``HOST:PORT`` (``[HOST]:PORT`` for IPv6), as ``omniloop ssl`` takes it."""
    host, port = parse_address(a)
    return f"[{host}]:{port}" if ":" in host else f"{host}:{port}"


def _family(host: str) -> socket.AddressFamily:
    return socket.AF_INET6 if ":" in host else socket.AF_INET


def _is_multicast(host: str) -> bool:
    try:
        return ipaddress.ip_address(host).is_multicast
    except ValueError:  # a host name
        return False


class SslTimeout(TimeoutError):
    """No answer came from the simulator in time."""


# --------------------------------------------------------------------------------------------
# The client of the three ports.


class SslClient:
    """A client of a simulator's three ports: ``control`` (simulation control), ``blue`` and
    ``yellow`` (robot control), each an address. Each request waits ``timeout_s`` for its
    answer, then raises ``SslTimeout``; answers to earlier requests that came late are
    dropped first. Positions are in metres, velocities in m/s and rad/s, as the protocol
    has them. A context manager: ``with SslClient(...) as c:`` closes its sockets."""

    def __init__(
        self,
        control: AddressLike,
        blue: AddressLike,
        yellow: AddressLike,
        *,
        timeout_s: float = 1.0,
    ) -> None:
        self.addresses: Dict[str, Address] = {
            "control": parse_address(control),
            "blue": parse_address(blue),
            "yellow": parse_address(yellow),
        }
        self.timeout_s = timeout_s
        self._sockets: Dict[str, socket.socket] = {}
        for name, addr in self.addresses.items():
            s = socket.socket(_family(addr[0]), socket.SOCK_DGRAM)
            s.connect(addr)
            self._sockets[name] = s

    def __enter__(self) -> "SslClient":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Closes the sockets."""
        for s in self._sockets.values():
            s.close()
        self._sockets.clear()

    def _port(self, port: Union[str, int]) -> str:
        if isinstance(port, str) and port.lower() == "control":
            return "control"
        return team_of(port).name.lower()

    def request(self, port: Union[str, int], payload: bytes) -> bytes:
        """Sends ``payload`` to ``port`` (``"control"``, ``"blue"`` or ``"yellow"``) and
        returns the answer's bytes."""
        name = self._port(port)
        s = self._sockets[name]
        s.setblocking(False)
        with contextlib.suppress(BlockingIOError, ConnectionRefusedError):
            while True:
                s.recv(65536)
        s.setblocking(True)
        s.send(payload)
        s.settimeout(self.timeout_s)
        try:
            return s.recv(65536)
        except socket.timeout:
            raise SslTimeout(
                f"no answer from the {name} port {self.addresses[name]} in {self.timeout_s} s"
            ) from None
        except ConnectionRefusedError:
            raise ConnectionRefusedError(
                f"nothing listens on the {name} port {self.addresses[name]}"
            ) from None

    def simulator_command(self, command: Any) -> Any:
        """Sends a ``SimulatorCommand`` to the control port; its ``SimulatorResponse``."""
        return SimulatorResponse.FromString(
            self.request("control", command.SerializeToString())
        )

    def teleport_ball(
        self,
        x_m: float,
        y_m: float,
        vx: float = 0.0,
        vy: float = 0.0,
        *,
        teleport_safely: bool = False,
    ) -> Any:
        """Puts the ball at (``x_m``, ``y_m``), m, rolling at (``vx``, ``vy``), m/s;
        ``teleport_safely`` moves robots out of its way. The ``SimulatorResponse``."""
        c = SimulatorCommand()
        b = c.control.teleport_ball
        b.x, b.y, b.vx, b.vy = x_m, y_m, vx, vy
        if teleport_safely:
            b.teleport_safely = True
        return self.simulator_command(c)

    def referee_command(self, command: int, *, source: str = "omniloop.ssl") -> Any:
        """Sets the referee's command (a ``Command``) at once, as a game controller's
        ``Referee`` message to the control port does (``source`` is its
        ``source_identifier``). The ``SimulatorResponse``."""
        r = Referee(
            packet_timestamp=int(time.time() * 1e6),
            stage=int(Stage.NORMAL_FIRST_HALF),
            command=int(command),
            command_counter=0,
            command_timestamp=int(time.time() * 1e6),
            source_identifier=source,
        )
        for team, name in ((r.yellow, "yellow"), (r.blue, "blue")):
            team.name = name
            team.score = team.red_cards = team.yellow_cards = team.goalkeeper = 0
            team.timeouts = team.timeout_time = 0
        return SimulatorResponse.FromString(self.request("control", r.SerializeToString()))

    def teleport_robot(
        self,
        team: TeamLike,
        id: int,
        x_m: float,
        y_m: float,
        orientation_rad: float,
        present: bool = True,
    ) -> Any:
        """Puts robot ``id`` of ``team`` at (``x_m``, ``y_m``), m, heading ``orientation_rad``
        counter-clockwise from the field's x, at rest; ``present=False`` takes it off the
        field. The ``SimulatorResponse``."""
        return self.teleport_robots([(team, id, x_m, y_m, orientation_rad, present)])

    def teleport_robots(
        self, robots: Sequence[Tuple[TeamLike, int, float, float, float, bool]]
    ) -> Any:
        """Teleports several robots in one command: each ``(team, id, x_m, y_m,
        orientation_rad, present)``. The ``SimulatorResponse``."""
        c = SimulatorCommand()
        for team, id, x, y, orientation, present in robots:
            t = c.control.teleport_robot.add()
            t.id.id = id
            t.id.team = int(team_of(team))
            t.x, t.y, t.orientation, t.present = x, y, orientation, present
        return self.simulator_command(c)

    def command(self, team: TeamLike, commands: Sequence[Any]) -> Any:
        """Sends ``team``'s ``RobotCommand``\\ s (``local_velocity``, ...) to its port; the
        ``RobotControlResponse``: ``errors`` and each robot's ``feedback``. In lockstep the
        commands hold until the next step (an empty list there reads as a sync request: use
        ``sync``)."""
        control = RobotControl()
        control.robot_commands.extend(commands)
        return RobotControlResponse.FromString(
            self.request(team, control.SerializeToString())
        )

    def sync(
        self,
        port: Union[str, int],
        sim_step_s: float,
        commands: Optional[Sequence[Any]] = None,
        *,
        simulator_command: Any = None,
    ) -> Any:
        """Lockstep: applies ``commands`` (a team port's ``RobotCommand``\\ s) and
        ``simulator_command``, then advances the simulation by ``sim_step_s`` (0: not at
        all). ``port`` is ``"control"`` (no commands then), ``"blue"`` or ``"yellow"``. The
        ``SimulationSyncResponse``: the step's ``detection`` frames (mm) and a
        ``robot_control_response`` (errors; on a team's port its feedback)."""
        r = SimulationSyncRequest(sim_step=sim_step_s)
        if commands is not None:
            r.robot_control.SetInParent()
            r.robot_control.robot_commands.extend(commands)
        if simulator_command is not None:
            r.simulator_command.CopyFrom(simulator_command)
        return SimulationSyncResponse.FromString(self.request(port, r.SerializeToString()))


# --------------------------------------------------------------------------------------------
# Vision and the referee.


_R = TypeVar("_R", bound="_Receiver")


class _Receiver:
    """A UDP socket bound to an address (a multicast group joined on all interfaces)."""

    def __init__(self, addr: AddressLike = ("127.0.0.1", 0)) -> None:
        host, port = parse_address(addr)
        self.sock = socket.socket(_family(host), socket.SOCK_DGRAM)
        multicast = _family(host) == socket.AF_INET and _is_multicast(host)
        if multicast:
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.bind(("" if multicast else host, port))
        if multicast:
            mreq = struct.pack("4s4s", socket.inet_aton(host), socket.inet_aton("0.0.0.0"))
            self.sock.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, mreq)
        self.address: Address = (host, self.sock.getsockname()[1])
        """Where it listens (the port bound when 0 was asked for)."""
        self.packets = 0
        """Datagrams received."""
        self.malformed = 0
        """Datagrams that did not parse."""
        self.largest = 0
        """The largest datagram received, bytes."""

    def __enter__(self: _R) -> _R:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def close(self) -> None:
        """Closes the socket."""
        self.sock.close()

    @property
    def address_text(self) -> str:
        """``HOST:PORT``, as ``omniloop ssl --vision``/``--referee`` take it."""
        return address_text(self.address)

    def receive_bytes(self, timeout_s: Optional[float] = 1.0) -> Optional[bytes]:
        """The next datagram; ``None`` after ``timeout_s`` (0: only one already here)."""
        if timeout_s is not None and timeout_s <= 0:
            self.sock.setblocking(False)
        else:
            self.sock.settimeout(timeout_s)
        try:
            data = self.sock.recv(65536)
        except (socket.timeout, BlockingIOError):
            return None
        self.packets += 1
        self.largest = max(self.largest, len(data))
        return data

    def _parse(self, cls: Any, data: bytes) -> Any:
        try:
            return cls.FromString(data)
        except Exception:  # protobuf's DecodeError, or a missing required field
            self.malformed += 1
            return None

    def _next(self, cls: Any, timeout_s: Optional[float]) -> Any:
        """The next datagram that parses as ``cls`` (``None`` after ``timeout_s``)."""
        deadline = None if timeout_s is None else time.monotonic() + max(0.0, timeout_s)
        while True:
            left = None if deadline is None else max(0.0, deadline - time.monotonic())
            data = self.receive_bytes(left)
            if data is None:
                return None
            p = self._parse(cls, data)
            if p is not None:
                return p


@dataclass
class RobotSeen:
    """A robot as vision saw it last: position in mm, orientation in rad, the capture's time
    (s, the sender's clock) and how many cameras saw it then."""

    x_mm: float
    y_mm: float
    orientation_rad: float
    t_capture: float
    cameras: int = 1


class VisionState:
    """What the latest detection frames say: each robot (by team and id) and the ball, from
    the newest capture that saw it (averaged over the cameras that saw it at that capture)."""

    def __init__(self) -> None:
        self.robots: Dict[Tuple[Team, int], RobotSeen] = {}
        """Each robot seen, by ``(Team, id)``."""
        self.ball: Optional[Tuple[float, float]] = None
        """The ball's position, mm."""
        self.ball_t: float = -math.inf
        """When the ball was captured last, s."""
        self._ball_n = 0
        self.frames = 0
        """Detection frames taken."""

    def update(self, frame: Any) -> None:
        """Takes an ``SSL_DetectionFrame``."""
        self.frames += 1
        t = float(frame.t_capture)
        for team, robots in ((Team.BLUE, frame.robots_blue), (Team.YELLOW, frame.robots_yellow)):
            for r in robots:
                key = (team, int(r.robot_id))
                old = self.robots.get(key)
                if old is None or t > old.t_capture + 1e-9:
                    self.robots[key] = RobotSeen(float(r.x), float(r.y), float(r.orientation), t)
                elif abs(t - old.t_capture) <= 1e-9:
                    n = old.cameras
                    old.x_mm = (old.x_mm * n + float(r.x)) / (n + 1)
                    old.y_mm = (old.y_mm * n + float(r.y)) / (n + 1)
                    old.cameras = n + 1
        if len(frame.balls) > 0:
            b = max(frame.balls, key=lambda b: b.confidence)
            if self.ball is None or t > self.ball_t + 1e-9:
                self.ball, self.ball_t, self._ball_n = (float(b.x), float(b.y)), t, 1
            elif abs(t - self.ball_t) <= 1e-9:
                n = self._ball_n
                self.ball = (
                    (self.ball[0] * n + float(b.x)) / (n + 1),
                    (self.ball[1] * n + float(b.y)) / (n + 1),
                )
                self._ball_n = n + 1

    def robot(self, team: TeamLike, id: int) -> Optional[RobotSeen]:
        """Robot ``id`` of ``team`` as last seen, or ``None``."""
        return self.robots.get((team_of(team), id))


class VisionReceiver(_Receiver):
    """ssl-vision's packets (``SSL_WrapperPacket``) arriving at ``addr``: ``receive`` takes
    one, ``poll`` everything waiting. Every detection frame goes into ``state``
    (``VisionState``) and the last geometry into ``geometry``."""

    def __init__(self, addr: AddressLike = ("127.0.0.1", 0)) -> None:
        super().__init__(addr)
        self.state = VisionState()
        """The robots and the ball as the frames so far saw them."""
        self.geometry: Any = None
        """The last ``SSL_GeometryData`` received."""
        self.largest_detection = 0
        """The largest packet holding a detection frame, bytes."""

    def receive(self, timeout_s: Optional[float] = 1.0) -> Any:
        """The next ``SSL_WrapperPacket`` (``None`` after ``timeout_s``; 0: only one already
        here). A datagram that does not parse is counted in ``malformed`` and skipped."""
        deadline = None if timeout_s is None else time.monotonic() + max(0.0, timeout_s)
        while True:
            left = None if deadline is None else max(0.0, deadline - time.monotonic())
            data = self.receive_bytes(left)
            if data is None:
                return None
            p = self._parse(SSL_WrapperPacket, data)
            if p is None:
                continue
            if p.HasField("detection"):
                self.largest_detection = max(self.largest_detection, len(data))
                self.state.update(p.detection)
            if p.HasField("geometry"):
                self.geometry = p.geometry
            return p

    def poll(self) -> List[Any]:
        """Every packet waiting now."""
        out: List[Any] = []
        while True:
            p = self.receive(0.0)
            if p is None:
                return out
            out.append(p)


class RefereeReceiver(_Receiver):
    """The referee's packets (``Referee``) arriving at ``addr``; ``latest`` is the last one."""

    def __init__(self, addr: AddressLike = ("127.0.0.1", 0)) -> None:
        super().__init__(addr)
        self.latest: Any = None
        """The last ``Referee`` received."""

    def receive(self, timeout_s: Optional[float] = 1.0) -> Any:
        """The next ``Referee`` packet (``None`` after ``timeout_s``; 0: only one already
        here)."""
        p = self._next(Referee, timeout_s)
        if p is not None:
            self.latest = p
        return p

    def poll(self) -> Any:
        """Takes every packet waiting; the latest packet so far (``None`` before any)."""
        while self.receive(0.0) is not None:
            pass
        return self.latest

    def score(self) -> Tuple[int, int]:
        """Goals of blue and of yellow by the latest packet (0, 0 before any)."""
        if self.latest is None:
            return (0, 0)
        return (int(self.latest.blue.score), int(self.latest.yellow.score))


# --------------------------------------------------------------------------------------------
# Running the simulator.

_REPOSITORY = Path(__file__).resolve().parents[2]


def binary_path(binary: Union[str, "os.PathLike[str]", None] = None) -> Path:
    """The ``omniloop`` binary: ``binary``, else ``$OMNILOOP_BIN``, else ``omniloop`` on the
    ``PATH``, else the repository's ``target/debug/omniloop`` (``cargo build``).
    ``FileNotFoundError`` naming the places looked at when none is there (or when ``binary``
    or ``$OMNILOOP_BIN``, set, is not an executable file)."""

    def runnable(p: Path) -> bool:
        return p.is_file() and os.access(p, os.X_OK)

    for what, chosen in (("binary=", binary), ("$OMNILOOP_BIN", os.environ.get("OMNILOOP_BIN"))):
        if chosen is not None and os.fspath(chosen) != "":
            if runnable(Path(chosen)):
                return Path(chosen)
            raise FileNotFoundError(f"{what} {os.fspath(chosen)}: not an executable file")
    on_path = shutil.which("omniloop")
    if on_path is not None:
        return Path(on_path)
    built = _REPOSITORY / "target" / "debug" / "omniloop"
    if runnable(built):
        return built
    raise FileNotFoundError(
        "no omniloop binary: not given (binary=), $OMNILOOP_BIN not set, no omniloop on the "
        f"PATH, and no {built} (build it with `cargo build`)"
    )


@dataclass
class Served:
    """A running ``omniloop ssl``: its ports' addresses (``control``, ``blue``, ``yellow``,
    and where it sends ``vision`` and the ``referee``), its process, its output folder and
    the file its standard error goes to (in ``serve``'s temporary folder: read it before
    leaving)."""

    control: Address
    blue: Address
    yellow: Address
    vision: Address
    referee: Address
    process: "subprocess.Popen[bytes]"
    out: Path
    log: Path

    def client(self, *, timeout_s: float = 1.0) -> SslClient:
        """An ``SslClient`` of its ports."""
        return SslClient(self.control, self.blue, self.yellow, timeout_s=timeout_s)

    def wait(self, timeout_s: Optional[float] = None) -> int:
        """Waits for it to end by itself (``--duration-s``, ``--idle-exit-s``); its exit
        status. ``subprocess.TimeoutExpired`` after ``timeout_s``."""
        return self.process.wait(timeout_s)

    def stderr(self) -> str:
        """What it wrote to standard error and standard output so far."""
        try:
            return self.log.read_text(errors="replace")
        except OSError:
            return ""

    def stop(self, timeout_s: float = 30.0) -> int:
        """Stops it as Ctrl-C does (it writes its files), killed after ``timeout_s``; its exit
        status."""
        return _stop(self.process, timeout_s)


def _stop(process: "subprocess.Popen[bytes]", timeout_s: float) -> int:
    """Interrupts ``process`` unless it ended, kills it after ``timeout_s``; its status."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(timeout_s)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
    return int(process.returncode)


@contextlib.contextmanager
def serve(
    scenario: Union[str, "os.PathLike[str]"],
    *,
    lockstep: bool = False,
    extra_args: Sequence[str] = (),
    binary: Union[str, "os.PathLike[str]", None] = None,
    vision: Optional[AddressLike] = None,
    referee: Optional[AddressLike] = None,
    out: Union[str, "os.PathLike[str]", None] = None,
    bind: str = "127.0.0.1",
    startup_timeout_s: float = 60.0,
) -> Iterator[Served]:
    """Runs ``omniloop ssl scenario`` on free ports of ``bind`` (``lockstep``: the simulation
    advances only on sync requests) and gives its addresses (``Served``) once they are bound;
    stops it on leaving (as Ctrl-C does) unless it ended already. ``vision`` and ``referee``
    are where it sends those packets (default: the scenario's, the league's multicast
    groups); ``out`` its output folder (default: in a temporary folder removed on leaving);
    ``extra_args`` more of its options (``--no-cameras``, ``--realism``, ``--seed``, ...).
    The binary is found by ``binary_path(binary)``. ``RuntimeError`` with its standard error
    when it ends before binding its ports."""
    exe = binary_path(binary)
    with tempfile.TemporaryDirectory(prefix="omniloop-ssl-") as tmp:
        ports_file = Path(tmp) / "ports.json"
        log = Path(tmp) / "stderr.txt"
        out_dir = Path(out) if out is not None else Path(tmp) / "out"
        args = [str(exe), "ssl", os.fspath(scenario), "--bind", bind, "--ports-file"]
        args += [str(ports_file), "--out", str(out_dir)]
        args += ["--control-port", "0", "--blue-port", "0", "--yellow-port", "0"]
        if lockstep:
            args.append("--lockstep")
        if vision is not None:
            args += ["--vision", address_text(vision)]
        if referee is not None:
            args += ["--referee", address_text(referee)]
        args += list(extra_args)
        with open(log, "wb") as log_file:
            process = subprocess.Popen(
                args, stdout=log_file, stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL
            )
        try:
            ports = _wait_for_ports(ports_file, process, startup_timeout_s, log)
            yield Served(
                control=parse_address(ports["control"]),
                blue=parse_address(ports["blue"]),
                yellow=parse_address(ports["yellow"]),
                vision=parse_address(ports["vision"]),
                referee=parse_address(ports["referee"]),
                process=process,
                out=out_dir,
                log=log,
            )
        finally:
            _stop(process, 30.0)


def _wait_for_ports(
    ports_file: Path, process: "subprocess.Popen[bytes]", timeout_s: float, log: Path
) -> Dict[str, str]:
    """The ports file's content once written whole."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if ports_file.exists():
            try:
                ports = json.loads(ports_file.read_text())
                if all(k in ports for k in ("control", "blue", "yellow", "vision", "referee")):
                    return {k: str(v) for k, v in ports.items()}
            except (ValueError, OSError):
                pass  # being written
        if process.poll() is not None:
            raise RuntimeError(
                f"omniloop ssl ended ({process.returncode}) before binding its ports:\n"
                + log.read_text(errors="replace")[-4000:]
            )
        time.sleep(0.01)
    process.kill()
    process.wait()
    raise RuntimeError(
        f"omniloop ssl did not bind its ports in {timeout_s} s:\n"
        + log.read_text(errors="replace")[-4000:]
    )
