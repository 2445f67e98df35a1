//! Camera model files in their tools' own formats: OpenCV's `cv::FileStorage` YAML for the
//! `omnidir` module and Kalibr's camchain YAML.

use super::double_sphere::DoubleSphereModel;
use super::unified::UnifiedModel;
use nalgebra::{Matrix3, Vector3};

/// Where a model's frame sits on the robot: `p_body = rotation * p_model + translation_mm`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelPose {
    /// Rotation from the model's frame to the robot's body frame.
    pub rotation: Matrix3<f64>,
    /// The model's viewpoint in the body frame (mm).
    pub translation_mm: Vector3<f64>,
}

impl ModelPose {
    /// The pose as comment lines (`# ...`).
    pub fn comment_lines(&self) -> String {
        let r = &self.rotation;
        let t = &self.translation_mm;
        let mut s = String::from(
            "# The model's frame on the robot: p_body = R p_model + t (body frame: x forward,\n\
             # y left, z up, origin on the floor at the robot's centre; mm).\n",
        );
        for i in 0..3 {
            s += &format!(
                "#   R[{i}] = [{:?}, {:?}, {:?}]\n",
                r[(i, 0)],
                r[(i, 1)],
                r[(i, 2)]
            );
        }
        s + &format!("#   t = [{:?}, {:?}, {:?}] mm\n", t.x, t.y, t.z)
    }
}

/// An `!!opencv-matrix` entry of `rows` x `cols` doubles.
fn opencv_matrix(name: &str, rows: usize, cols: usize, data: &[f64]) -> String {
    let data: Vec<String> = data.iter().map(|v| format!("{v:?}")).collect();
    format!(
        "{name}: !!opencv-matrix\n   rows: {rows}\n   cols: {cols}\n   dt: d\n   data: [ {} ]\n",
        data.join(", ")
    )
}

/// The model as OpenCV `omnidir` reads it with `cv::FileStorage`: `K` (3x3), `xi` (1x1), `D`
/// (1x4: k1, k2, p1, p2), `image_width`, `image_height`; `header` and the pose as comments.
pub fn opencv_omnidir_yaml(
    model: &UnifiedModel,
    size_px: [u32; 2],
    pose: &ModelPose,
    header: &str,
) -> String {
    let [fx, fy] = model.focal_px;
    let [cx, cy] = model.principal_px;
    let k = [fx, model.skew_px, cx, 0.0, fy, cy, 0.0, 0.0, 1.0];
    let mut s = String::from("%YAML:1.0\n---\n");
    for line in header.lines() {
        s += &format!("# {line}\n");
    }
    s += &pose.comment_lines();
    s += &format!(
        "image_width: {}\nimage_height: {}\n",
        size_px[0], size_px[1]
    );
    s += &opencv_matrix("K", 3, 3, &k);
    s += &opencv_matrix("xi", 1, 1, &[model.xi]);
    s += &opencv_matrix("D", 1, 4, &model.distortion);
    s
}

/// The model as a Kalibr camchain (`camera_model: omni`, `distortion_model: radtan`), the
/// body frame in the place of Kalibr's IMU: `T_cam_imu` takes body points to the model's
/// frame, in metres as Kalibr has it.
pub fn kalibr_omni_yaml(
    model: &UnifiedModel,
    size_px: [u32; 2],
    pose: &ModelPose,
    topic: &str,
    header: &str,
) -> String {
    let [fx, fy] = model.focal_px;
    let [cx, cy] = model.principal_px;
    let camera = KalibrCamera {
        model: "omni",
        intrinsics: vec![model.xi, fx, fy, cx, cy],
        distortion: ("radtan", model.distortion.to_vec()),
    };
    kalibr_yaml(&camera, size_px, pose, topic, header)
}

/// The model as a Kalibr camchain with `camera_model: ds` (`intrinsics: [xi, alpha, f_u, f_v,
/// p_u, p_v]`, no distortion), as [`kalibr_omni_yaml`] otherwise.
pub fn kalibr_ds_yaml(
    model: &DoubleSphereModel,
    size_px: [u32; 2],
    pose: &ModelPose,
    topic: &str,
    header: &str,
) -> String {
    let [fx, fy] = model.focal_px;
    let [cx, cy] = model.principal_px;
    let camera = KalibrCamera {
        model: "ds",
        intrinsics: vec![model.xi, model.alpha, fx, fy, cx, cy],
        distortion: ("none", Vec::new()),
    };
    kalibr_yaml(&camera, size_px, pose, topic, header)
}

/// One camera of a Kalibr camchain.
struct KalibrCamera {
    model: &'static str,
    intrinsics: Vec<f64>,
    distortion: (&'static str, Vec<f64>),
}

fn yaml_list(values: &[f64]) -> String {
    let v: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
    format!("[{}]", v.join(", "))
}

fn kalibr_yaml(
    camera: &KalibrCamera,
    size_px: [u32; 2],
    pose: &ModelPose,
    topic: &str,
    header: &str,
) -> String {
    // p_model = R^T (p_body - t).
    let r = pose.rotation.transpose();
    let t = -(r * pose.translation_mm) / 1000.0;
    let mut s = String::new();
    for line in header.lines() {
        s += &format!("# {line}\n");
    }
    s += &pose.comment_lines();
    s += &format!("cam0:\n  camera_model: {}\n", camera.model);
    s += &format!("  intrinsics: {}\n", yaml_list(&camera.intrinsics));
    s += &format!("  distortion_model: {}\n", camera.distortion.0);
    s += &format!("  distortion_coeffs: {}\n", yaml_list(&camera.distortion.1));
    s += &format!("  resolution: [{}, {}]\n", size_px[0], size_px[1]);
    s += &format!("  rostopic: {topic}\n  T_cam_imu:\n");
    for i in 0..3 {
        let row = [r[(i, 0)], r[(i, 1)], r[(i, 2)], t[i]];
        s += &format!("  - {}\n", yaml_list(&row));
    }
    s + "  - [0.0, 0.0, 0.0, 1.0]\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model() -> UnifiedModel {
        UnifiedModel {
            focal_px: [300.0, 301.0],
            skew_px: 0.0,
            principal_px: [127.5, 109.5],
            xi: 0.95,
            distortion: [0.01, 0.0, 0.0, 0.0],
        }
    }

    fn pose() -> ModelPose {
        ModelPose {
            rotation: Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0),
            translation_mm: Vector3::new(0.0, 0.0, 205.0),
        }
    }

    #[test]
    fn the_opencv_file_holds_k_xi_d_and_the_size() {
        let s = opencv_omnidir_yaml(&model(), [256, 220], &pose(), "made by a test");
        assert!(s.starts_with("%YAML:1.0\n---\n# made by a test\n"), "{s}");
        assert!(s.contains("K: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 300.0, 0.0, 127.5, 0.0, 301.0, 109.5, 0.0, 0.0, 1.0 ]"), "{s}");
        assert!(
            s.contains("xi: !!opencv-matrix\n   rows: 1\n   cols: 1\n   dt: d\n   data: [ 0.95 ]"),
            "{s}"
        );
        assert!(s.contains("data: [ 0.01, 0.0, 0.0, 0.0 ]"), "{s}");
        assert!(s.contains("image_width: 256\nimage_height: 220\n"), "{s}");
        assert!(s.contains("#   t = [0.0, 0.0, 205.0] mm"), "{s}");
    }

    #[test]
    fn kalibrs_transform_takes_the_viewpoint_to_the_origin() {
        let s = kalibr_omni_yaml(&model(), [256, 220], &pose(), "/camera/omni", "");
        assert!(
            s.contains("intrinsics: [0.95, 300.0, 301.0, 127.5, 109.5]"),
            "{s}"
        );
        // R^T = R for this rotation; -R^T t = (0, 0, 0.205) m.
        assert!(s.contains("  - [0.0, 0.0, -1.0, 0.205]"), "{s}");
        assert!(s.contains("resolution: [256, 220]"), "{s}");
    }
}
