//! `omniloop run --mcap`: E1 recorded as MCAP, read back with the `mcap` crate and Foxglove's
//! own decoders: every channel, a camera message a cycle, the true pose of cycle k equal to
//! `trajectory.csv`'s row k, the first frame equal to the `--save-frames` PNG of cycle 0, and
//! the same file from the same scenario and seed.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use crate::common;

use common::{omniloop, scenario_path, tmp};
use foxglove::Decode;
use foxglove::messages::{CompressedImage, PoseInFrame};
use std::collections::BTreeMap;

/// Runs E1 on the CPU into `dir` with the options `extra`.
fn run_e1(dir: &std::path::Path, extra: &[&str]) {
    let (file, out) = (
        scenario_path("corner55_velocity_aware.toml"),
        dir.display().to_string(),
    );
    let file = file.display().to_string();
    let mut args = vec![
        "run",
        file.as_str(),
        "--renderer",
        "cpu",
        "--out",
        out.as_str(),
        "-q",
    ];
    args.extend_from_slice(extra);
    omniloop(args);
}

/// Runs E1 into `dir` with `--mcap` and `--save-frames`; the MCAP file's bytes.
fn record(dir: &std::path::Path) -> Vec<u8> {
    run_e1(dir, &["--mcap", "--save-frames"]);
    std::fs::read(dir.join("run.mcap")).unwrap()
}

#[test]
fn e1_recorded_as_mcap_reads_back_as_the_run() {
    let dir = tmp("mcap_e1");
    let bytes = record(&dir);
    let mut by_topic: BTreeMap<String, Vec<(u64, Vec<u8>)>> = BTreeMap::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        by_topic
            .entry(m.channel.topic.clone())
            .or_default()
            .push((m.log_time, m.data.into_owned()));
    }
    let counts: BTreeMap<&String, usize> = by_topic.iter().map(|(t, v)| (t, v.len())).collect();
    eprintln!("{counts:?}");
    let trajectory = std::fs::read_to_string(dir.join("trajectory.csv")).unwrap();
    let rows: Vec<Vec<f64>> = trajectory
        .lines()
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|v| v.parse().unwrap_or(f64::NAN))
                .collect()
        })
        .collect();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap();
    let cycles = summary["cycles"].as_u64().unwrap() as usize;
    for topic in [
        "/camera/omni",
        "/truth/pose",
        "/truth/tf",
        "/estimate/pose",
        "/estimate/tf",
        "/estimate/error",
        "/estimate/free_space",
        "/command",
        "/estimate/record",
    ] {
        assert_eq!(
            counts.get(&topic.to_string()),
            Some(&cycles),
            "{topic}: {counts:?}"
        );
    }
    assert_eq!(counts.get(&"/world".to_string()), Some(&1));
    assert_eq!(counts.get(&"/summary".to_string()), Some(&1));
    // The true pose of every cycle is trajectory.csv's row, in metres; times are simulation times.
    for (k, (t_ns, data)) in by_topic["/truth/pose"].iter().enumerate() {
        let p = PoseInFrame::decode(&data[..]).unwrap();
        let pos = p.pose.unwrap().position.unwrap();
        let row = &rows[k];
        assert!(
            (*t_ns as f64 * 1e-9 - row[0]).abs() < 1e-6,
            "cycle {k}: {t_ns} ns"
        );
        assert!((pos.x * 1e3 - row[1]).abs() < 1e-6 && (pos.y * 1e3 - row[2]).abs() < 1e-6);
    }
    // The first frame is the PNG --save-frames wrote for cycle 0, pixel for pixel.
    let first = CompressedImage::decode(&by_topic["/camera/omni"][0].1[..]).unwrap();
    assert_eq!(first.format, "png");
    let from_mcap = image::load_from_memory(&first.data).unwrap().to_rgba8();
    let saved = image::open(dir.join("frames").join("omni_000000.png"))
        .unwrap()
        .to_rgba8();
    assert!(
        from_mcap == saved,
        "the first frame differs from omni_000000.png"
    );
    // The same scenario and seed give the same file.
    assert!(
        record(&tmp("mcap_e1_again")) == bytes,
        "a second recording differs"
    );
}

/// `omniloop run --gif`: E1 as an animation of every fifth cycle (42 frames for 207 cycles),
/// each the camera beside the top view, shown 200 ms (five 40 ms periods), a few MB.
#[test]
fn e1_as_an_animated_gif() {
    use image::AnimationDecoder;
    let dir = tmp("gif_e1");
    run_e1(&dir, &["--gif"]);
    let gif = dir.join("run.gif");
    let size = std::fs::metadata(&gif).unwrap().len();
    let reader = std::io::BufReader::new(std::fs::File::open(&gif).unwrap());
    let frames = image::codecs::gif::GifDecoder::new(reader)
        .unwrap()
        .into_frames()
        .collect_frames()
        .unwrap();
    eprintln!("{} frames, {:.1} MB", frames.len(), size as f64 / 1e6);
    assert_eq!(frames.len(), 207usize.div_ceil(5));
    assert!(size < 5_000_000, "{size} bytes");
    let (num, den) = frames[0].delay().numer_denom_ms();
    assert_eq!(num / den, 200);
    // The camera (256 x 220) on the left, the top view beside it.
    let first = frames[0].buffer();
    assert!(first.width() > 256 + 300 && first.height() >= 220);
}

/// A Foxglove WebSocket client's view of a served run: the true poses (x, y in m) it got on
/// `/truth/pose`, and whether `/summary` came last.
struct Watched {
    poses: Vec<(f64, f64)>,
    summary: bool,
}

/// Connects to `port` as the Foxglove app does (subprotocol `foxglove.sdk.v1`, the
/// `foxglove.websocket.v1` protocol's name in the Foxglove SDK), subscribes to `/truth/pose` (subscription 1)
/// and `/summary` (2), and reads until the summary comes or the server closes.
fn watch(port: u16) -> Watched {
    use tungstenite::Message;
    use tungstenite::client::IntoClientRequest;
    let mut request = format!("ws://127.0.0.1:{port}")
        .into_client_request()
        .unwrap();
    request
        .headers_mut()
        .insert("Sec-WebSocket-Protocol", "foxglove.sdk.v1".parse().unwrap());
    let (mut ws, _) = tungstenite::connect(request).unwrap();
    let mut ids: BTreeMap<String, u64> = BTreeMap::new();
    while !(ids.contains_key("/truth/pose") && ids.contains_key("/summary")) {
        if let Message::Text(text) = ws.read().unwrap() {
            let m: serde_json::Value = serde_json::from_str(&text).unwrap();
            if m["op"] == "advertise" {
                for c in m["channels"].as_array().unwrap() {
                    ids.insert(
                        c["topic"].as_str().unwrap().into(),
                        c["id"].as_u64().unwrap(),
                    );
                }
            }
        }
    }
    let subscribe = serde_json::json!({"op": "subscribe", "subscriptions": [
        {"id": 1, "channelId": ids["/truth/pose"]},
        {"id": 2, "channelId": ids["/summary"]},
    ]});
    ws.send(Message::text(subscribe.to_string())).unwrap();
    let mut watched = Watched {
        poses: Vec::new(),
        summary: false,
    };
    while let Ok(m) = ws.read() {
        let Message::Binary(b) = m else { continue };
        // Message data: opcode 1, subscription id (u32), log time (u64), payload; little-endian.
        assert_eq!(b[0], 1, "opcode");
        let sub = u32::from_le_bytes(b[1..5].try_into().unwrap());
        if sub == 2 {
            watched.summary = true;
            break;
        }
        let p = PoseInFrame::decode(&b[13..]).unwrap();
        let pos = p.pose.unwrap().position.unwrap();
        watched.poses.push((pos.x, pos.y));
    }
    let _ = ws.close(None);
    watched
}

/// A child process killed when the test stops early (a server waiting for a viewer that never
/// came would otherwise outlive it).
struct Reaped(std::process::Child);

impl Drop for Reaped {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// `omniloop run --live`: E1 served on a free loopback port waits for its viewer, which gets
/// the true pose of every cycle (trajectory.csv's rows but the final state's) and then the
/// summary; the run's
/// trajectory.csv is the run's without a viewer, byte for byte.
#[test]
fn e1_served_live_reaches_a_foxglove_client_a_pose_a_cycle() {
    use std::io::BufRead;
    let (live_dir, plain_dir) = (tmp("live_e1"), tmp("live_e1_plain"));
    let mut child = Reaped(
        common::bin()
            .arg("run")
            .arg(scenario_path("corner55_velocity_aware.toml"))
            .args([
                "--renderer",
                "cpu",
                "-q",
                "--live",
                "127.0.0.1:0",
                "--live-wait",
            ])
            .arg("--out")
            .arg(&live_dir)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap(),
    );
    let mut stderr = std::io::BufReader::new(child.0.stderr.take().unwrap());
    let mut line = String::new();
    let port: u16 = loop {
        line.clear();
        assert!(stderr.read_line(&mut line).unwrap() > 0, "no live address");
        if let Some(rest) = line.split("ws://127.0.0.1:").nth(1) {
            break rest.split_whitespace().next().unwrap().parse().unwrap();
        }
    };
    let drain = std::thread::spawn(move || std::io::read_to_string(stderr).unwrap());
    let watched = watch(port);
    let status = child.0.wait().unwrap();
    let messages = drain.join().unwrap();
    assert!(status.success(), "{status}: {messages}");
    run_e1(&plain_dir, &[]);
    let trajectory = std::fs::read_to_string(live_dir.join("trajectory.csv")).unwrap();
    assert!(
        trajectory == std::fs::read_to_string(plain_dir.join("trajectory.csv")).unwrap(),
        "trajectory.csv differs with a live viewer"
    );
    let rows: Vec<(f64, f64)> = trajectory
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').take(3).map(|v| v.parse().unwrap()).collect();
            (v[1], v[2])
        })
        .collect();
    // A row a cycle, then the final state.
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(live_dir.join("summary.json")).unwrap())
            .unwrap();
    let cycles = summary["cycles"].as_u64().unwrap() as usize;
    assert_eq!(rows.len(), cycles + 1);
    eprintln!("{} poses received for {cycles} cycles", watched.poses.len());
    assert!(watched.summary, "the summary did not come");
    assert_eq!(watched.poses.len(), cycles);
    for (k, (got, row)) in watched.poses.iter().zip(&rows).enumerate() {
        assert!(
            (got.0 * 1e3 - row.0).abs() < 1e-6 && (got.1 * 1e3 - row.1).abs() < 1e-6,
            "cycle {k}: {got:?} against {row:?}"
        );
    }
}

#[test]
fn the_ball_and_the_scripted_robots_are_moving_entities_in_the_mcap() {
    use foxglove::messages::SceneUpdate;
    let dir = tmp("mcap_ball");
    let file = scenario_path("ball_kick.toml").display().to_string();
    let out = dir.display().to_string();
    omniloop(["run", &file, "--out", &out, "--mcap", "-q"]);
    let bytes = std::fs::read(dir.join("run.mcap")).unwrap();
    let mut moving = Vec::new();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        if m.channel.topic == "/truth/moving" {
            moving.push(SceneUpdate::decode(&m.data[..]).unwrap());
        }
    }
    let csv = std::fs::read_to_string(dir.join("ball.csv")).unwrap();
    let rows: Vec<Vec<f64>> = (csv.lines().skip(1))
        .map(|l| l.split(',').take(3).map(|v| v.parse().unwrap()).collect())
        .collect();
    // A message a cycle (ball.csv has the final state besides), the ball where ball.csv has it.
    assert_eq!(moving.len() + 1, rows.len());
    for (k, update) in moving.iter().enumerate().step_by(25) {
        let sphere = &update.entities[0].spheres[0];
        let p = sphere.pose.as_ref().unwrap().position.as_ref().unwrap();
        assert!((p.x * 1000.0 - rows[k][1]).abs() < 1e-6, "cycle {k}");
        assert!((p.y * 1000.0 - rows[k][2]).abs() < 1e-6, "cycle {k}");
        assert!((sphere.size.as_ref().unwrap().x - 0.043).abs() < 1e-9);
    }
    // E1 has neither: no such channel (its other files stay as they were).
    let e1 = tmp("mcap_no_ball");
    let e1_bytes = record(&e1);
    let topics: Vec<String> = mcap::MessageStream::new(&e1_bytes)
        .unwrap()
        .map(|m| m.unwrap().channel.topic.clone())
        .collect();
    assert!(!topics.iter().any(|t| t == "/truth/moving"));
}
