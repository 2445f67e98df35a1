"""The exported camera model checked by OpenCV itself: `omniloop calibrate --format
opencv-omnidir` read with `cv::FileStorage`, floor points projected with
`cv2.omnidir.projectPoints`, against where the renderer images small marks placed there."""

import json
import os
import shutil
import subprocess
import tomllib
from pathlib import Path

import cv2
import numpy as np
import pytest

import omniloop

from conftest import ROOT, SCENARIOS


def omniloop_cli() -> str:
    """The command-line program: $OMNILOOP_BIN, else the one `cargo test` built, else PATH."""
    candidates = [os.environ.get("OMNILOOP_BIN")]
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    candidates += [str(target / p / "omniloop") for p in ("debug", "release")]
    candidates.append(shutil.which("omniloop"))
    for c in candidates:
        if c and Path(c).is_file():
            return c
    pytest.fail("the omniloop program is not built: run `cargo build` (or set OMNILOOP_BIN)")


def test_opencv_projects_floor_marks_where_the_renderer_images_them(tmp_path):
    scenario = SCENARIOS / "camera_check.toml"
    cli = omniloop_cli()
    png, yaml = tmp_path / "check.png", tmp_path / "check.yaml"
    subprocess.run(
        [cli, "render", scenario, "--renderer", "cpu", "--no-noise", "--out", png], check=True
    )
    subprocess.run(
        [cli, "calibrate", scenario, "--format", "opencv-omnidir", "--out", yaml], check=True
    )
    fs = cv2.FileStorage(str(yaml), cv2.FILE_STORAGE_READ)
    K, xi, D = (fs.getNode(k).mat() for k in ("K", "xi", "D"))
    assert K.shape == (3, 3) and xi.shape == (1, 1) and D.shape == (1, 4)
    assert (fs.getNode("image_width").real(), fs.getNode("image_height").real()) == (256, 220)
    # Floor points in the model's frame: p_model = R^T (p_body - t); the robot stands at the
    # origin facing +x, so body and world coincide.
    pose = json.loads(yaml.with_suffix(".json").read_text())["model_frame_in_body"]
    R, t = np.array(pose["rotation"]), np.array(pose["translation_mm"])
    marks = tomllib.loads(scenario.read_text())["world"]["floor_marks"]
    floor = np.array([m["center_mm"] + [0.0] for m in marks])
    in_model = (R.T @ (floor - t).T).T
    projected, _ = cv2.omnidir.projectPoints(
        in_model.reshape(-1, 1, 3), np.zeros(3), np.zeros(3), K, float(xi[0, 0]), D
    )
    projected = projected.reshape(-1, 2)
    # Each mark's darkness-weighted centroid in the clean frame.
    grey = cv2.imread(str(png), cv2.IMREAD_GRAYSCALE).astype(float)
    _, labels = cv2.connectedComponents((grey < 120).astype(np.uint8))
    weight = np.clip(200.0 - grey, 0.0, None)
    errors = []
    for u, v in projected:
        label = labels[int(round(v)), int(round(u))]
        assert label != 0, f"no mark imaged at ({u:.2f}, {v:.2f})"
        ys, xs = np.nonzero(labels == label)
        assert len(xs) < 200, f"the blob at ({u:.2f}, {v:.2f}) is not a mark ({len(xs)} px)"
        w = weight[ys, xs]
        cu, cv = (xs * w).sum() / w.sum(), (ys * w).sum() / w.sum()
        errors.append(float(np.hypot(cu - u, cv - v)))
    assert len(errors) == 18
    assert max(errors) < 0.3, errors


def test_a_camera_known_by_its_opencv_file_drives_e1_as_the_cli_does(tmp_path):
    """`[robot.sensors.calibrated]` from Python: the scenario loads with its camera file, runs
    to the goal, and a broken file is a ScenarioError naming the file, line and field."""
    scenario = omniloop.Scenario.load(SCENARIOS / "corner55_calibrated.toml")
    assert scenario.robot["sensors"][0]["kind"] == "calibrated"
    s = omniloop.run(scenario).summary
    assert s["reached_goal"] is True and s["wall_contacts"] == 0
    (tmp_path / "cameras").mkdir()
    good = (SCENARIOS / "cameras" / "corner_omni.opencv.yaml").read_text()
    (tmp_path / "cameras" / "corner_omni.opencv.yaml").write_text(good.replace("\nD:", "\nE:"))
    bad = tmp_path / "calibrated.toml"
    bad.write_text((SCENARIOS / "corner55_calibrated.toml").read_text())
    with pytest.raises(omniloop.ScenarioError) as e:
        omniloop.Scenario.load(bad)
    assert f"{bad}:" in str(e.value)
    assert "field `robot.sensors[0].calibrated.file`" in str(e.value)
    assert "corner_omni.opencv.yaml: line " in str(e.value)
    assert "field `D`: missing" in str(e.value)
