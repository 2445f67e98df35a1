//! Reading camera model files in their tools' formats (the files [`super::files`] and
//! [`super::OcamModel::calib_results_txt`] write, and the tools' own): every problem is an
//! error naming the file, the line and the field.

use super::double_sphere::DoubleSphereModel;
use super::ocamcalib::{OcamModel, PolynomialError};
use super::unified::UnifiedModel;
use crate::VisionError;
use std::path::Path;
use yaml_rust2::{ScanError, Yaml, YamlLoader};

/// A camera model read from a file, with its image size (width, height in px).
#[derive(Debug, Clone, PartialEq)]
pub enum CameraFile {
    /// Mei's unified model (OpenCV `omnidir`, Kalibr `omni`).
    Unified(UnifiedModel, [u32; 2]),
    /// The double sphere model (Kalibr `ds`).
    DoubleSphere(DoubleSphereModel, [u32; 2]),
    /// Scaramuzza's polynomial (OCamCalib; the size is in the model).
    Ocam(OcamModel),
}

impl CameraFile {
    /// The unit ray, in the model's frame, of the pixel at `[u, v]` (pixel centres at
    /// integers), or `None` where the model has no ray: each model's own unprojection.
    pub fn unproject(&self, pixel: [f64; 2]) -> Option<nalgebra::Vector3<f64>> {
        match self {
            CameraFile::Unified(m, _) => m.unproject(pixel),
            CameraFile::DoubleSphere(m, _) => m.unproject(pixel),
            CameraFile::Ocam(m) => Some(m.cam2world(pixel[1], pixel[0])),
        }
    }

    /// The principal point `[u, v]` (px, pixel centres at integers): where the optical axis
    /// images.
    pub fn principal_px(&self) -> [f64; 2] {
        match self {
            CameraFile::Unified(m, _) => m.principal_px,
            CameraFile::DoubleSphere(m, _) => m.principal_px,
            CameraFile::Ocam(m) => [m.center_rc[1], m.center_rc[0]],
        }
    }

    /// The image size the model was calibrated for: width, height (px).
    pub fn size_px(&self) -> [u32; 2] {
        match self {
            CameraFile::Unified(_, size) | CameraFile::DoubleSphere(_, size) => *size,
            CameraFile::Ocam(m) => [m.size_hw[1], m.size_hw[0]],
        }
    }
}

/// The formats [`read_camera_file`] takes, by name.
pub const FORMATS: [&str; 4] = ["opencv-omnidir", "ocamcalib", "kalibr-omni", "kalibr-ds"];

/// Why a camera model file cannot be read: where in the file, and what is wrong there.
#[derive(Debug, thiserror::Error)]
pub enum CameraFileError {
    /// The file cannot be read at all.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A format that is none of [`FORMATS`].
    #[error("unknown camera model format {format:?} (one of: {})", FORMATS.join(", "))]
    UnknownFormat {
        /// The format asked for.
        format: String,
    },
    /// The text is not YAML (the YAML formats).
    #[error("line {line}: not YAML: {reason}")]
    NotYaml {
        /// 1-based line (the parser's).
        line: usize,
        /// What the parser said.
        reason: ScanError,
    },
    /// The file holds no document.
    #[error("line 1: the file is empty")]
    Empty,
    /// A Kalibr camchain read as an OpenCV `omnidir` file.
    #[error("line 1: this is a Kalibr camchain, not an OpenCV omnidir file")]
    KalibrCamchain,
    /// A field that is missing or wrong.
    #[error("line {line}, field `{field}`: {problem}")]
    Field {
        /// 1-based line of the field (1 when it is not in the file).
        line: usize,
        /// The field's name.
        field: &'static str,
        /// What is wrong with it.
        problem: FieldProblem,
    },
}

/// What is wrong with one field of a camera model file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum FieldProblem {
    /// Not in the file.
    #[error("missing")]
    Missing,
    /// Not in the mapping it belongs to.
    #[error("missing in `{0}`")]
    MissingIn(&'static str),
    /// A Kalibr camchain without its first camera.
    #[error("missing (a Kalibr camchain names its cameras cam0, cam1, ...)")]
    MissingCamera,
    /// Not a list.
    #[error("expected a list of {0} numbers")]
    NotAList(usize),
    /// A list of numbers of the wrong length.
    #[error("expected {expected} numbers, found {found}")]
    Count {
        /// How many it must have.
        expected: usize,
        /// How many it has.
        found: usize,
    },
    /// A list with something other than finite numbers in it.
    #[error("expected {0} finite numbers")]
    NotFinite(usize),
    /// A matrix of the wrong shape.
    #[error("a {rows}x{cols} matrix where {needed} values are needed")]
    MatrixShape {
        /// Its rows.
        rows: i64,
        /// Its columns.
        cols: i64,
        /// The values needed.
        needed: usize,
    },
    /// Not a whole number of pixels in `1..=65536`.
    #[error("expected a size in pixels")]
    NotASize,
    /// A focal length that is not positive.
    #[error("the focal lengths must be positive")]
    FocalLength,
    /// A Kalibr camera of another model than the format.
    #[error("{found:?} where format {format} needs {needed:?}")]
    WrongModel {
        /// The model the file names.
        found: String,
        /// The format asked for.
        format: String,
        /// The model that format needs.
        needed: &'static str,
    },
    /// A line of a `calib_results.txt` that is not numbers.
    #[error("expected numbers, found {0:?}")]
    NotNumbers(String),
    /// A polynomial's line whose count does not match its coefficients.
    #[error("a count and that many coefficients")]
    NotCounted,
    /// An image size that is not whole pixels.
    #[error("height and width in pixels")]
    NotPixelSize,
    /// An affine map without an inverse.
    #[error("c - d e is 0, the affine map has no inverse")]
    NoAffineInverse,
    /// A polynomial that does not give every pixel one ray.
    #[error(transparent)]
    Polynomial(#[from] PolynomialError),
}

/// Reads `path` as a camera model file of `format` (one of [`FORMATS`]).
pub fn read_camera_file(path: &Path, format: &str) -> Result<CameraFile, VisionError> {
    let in_file = |error: CameraFileError| VisionError::CameraFile {
        path: path.display().to_string(),
        error: Box::new(error),
    };
    let text = std::fs::read_to_string(path).map_err(|e| in_file(e.into()))?;
    parse_camera_file(&text, format).map_err(in_file)
}

/// Parses the text of a camera model file of `format`; the error says the line and field.
pub fn parse_camera_file(text: &str, format: &str) -> Result<CameraFile, CameraFileError> {
    match format {
        "opencv-omnidir" => parse_opencv(text),
        "ocamcalib" => parse_ocamcalib(text),
        "kalibr-omni" | "kalibr-ds" => parse_kalibr(text, format),
        other => Err(CameraFileError::UnknownFormat {
            format: other.to_string(),
        }),
    }
}

/// The 1-based line where `key:` first appears in `text` (1 when it does not).
fn line_of(text: &str, key: &str) -> usize {
    text.lines()
        .position(|l| {
            let l = l.trim_start().trim_start_matches("- ");
            l.strip_prefix(key)
                .is_some_and(|rest| rest.trim_start().starts_with(':'))
        })
        .map_or(1, |i| i + 1)
}

/// `problem` with the field `key`, at its line in `text`.
fn at_key(text: &str, key: &'static str, problem: FieldProblem) -> CameraFileError {
    CameraFileError::Field {
        line: line_of(text, key),
        field: key,
        problem,
    }
}

/// A YAML document; OpenCV's `%YAML:1.0` first line is read as a comment (it is not standard
/// YAML), so that line numbers stay the file's.
fn load_yaml(text: &str) -> Result<Yaml, CameraFileError> {
    let text = match text.strip_prefix("%YAML:1.0") {
        Some(rest) => format!("#{rest}"),
        None => text.to_string(),
    };
    let docs = YamlLoader::load_from_str(&text).map_err(|reason| CameraFileError::NotYaml {
        line: reason.marker().line(),
        reason,
    })?;
    docs.into_iter().next().ok_or(CameraFileError::Empty)
}

/// A number of a YAML value.
fn number(y: &Yaml) -> Option<f64> {
    match y {
        Yaml::Real(_) => y.as_f64(),
        Yaml::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

/// `n` numbers of a YAML list at `key` (its line for errors).
fn numbers(y: &Yaml, text: &str, key: &'static str, n: usize) -> Result<Vec<f64>, CameraFileError> {
    let list = y
        .as_vec()
        .ok_or_else(|| at_key(text, key, FieldProblem::NotAList(n)))?;
    let values: Option<Vec<f64>> = list.iter().map(number).collect();
    match values {
        Some(v) if v.len() == n && v.iter().all(|x| x.is_finite()) => Ok(v),
        Some(v) if v.len() != n => Err(at_key(
            text,
            key,
            FieldProblem::Count {
                expected: n,
                found: v.len(),
            },
        )),
        _ => Err(at_key(text, key, FieldProblem::NotFinite(n))),
    }
}

/// The field `key` of a mapping, or an error naming it (`missing`: what it says).
fn field<'a>(
    map: &'a Yaml,
    text: &str,
    key: &'static str,
    missing: FieldProblem,
) -> Result<&'a Yaml, CameraFileError> {
    let v = &map[key];
    if v.is_badvalue() {
        return Err(at_key(text, key, missing));
    }
    Ok(v)
}

/// An OpenCV matrix (`!!opencv-matrix` with `rows`, `cols`, `data`) of `n` values, or a plain
/// number for a 1x1 matrix.
fn opencv_matrix(
    doc: &Yaml,
    text: &str,
    key: &'static str,
    n: usize,
) -> Result<Vec<f64>, CameraFileError> {
    let m = field(doc, text, key, FieldProblem::Missing)?;
    if n == 1
        && let Some(v) = number(m)
    {
        return Ok(vec![v]);
    }
    let data = field(m, text, "data", FieldProblem::MissingIn(key))?;
    let values = numbers(data, text, key, n)?;
    let (rows, cols) = (m["rows"].as_i64(), m["cols"].as_i64());
    if let (Some(rows), Some(cols)) = (rows, cols)
        && (rows * cols) as usize != n
    {
        return Err(at_key(
            text,
            key,
            FieldProblem::MatrixShape {
                rows,
                cols,
                needed: n,
            },
        ));
    }
    Ok(values)
}

fn size_field(doc: &Yaml, text: &str, key: &'static str) -> Result<u32, CameraFileError> {
    let v = field(doc, text, key, FieldProblem::Missing)?;
    v.as_i64()
        .filter(|&n| n > 0 && n <= 1 << 16)
        .map(|n| n as u32)
        .ok_or_else(|| at_key(text, key, FieldProblem::NotASize))
}

fn parse_opencv(text: &str) -> Result<CameraFile, CameraFileError> {
    let doc = load_yaml(text)?;
    if doc["cam0"].as_hash().is_some() {
        return Err(CameraFileError::KalibrCamchain);
    }
    let k = opencv_matrix(&doc, text, "K", 9)?;
    let xi = opencv_matrix(&doc, text, "xi", 1)?[0];
    let d = opencv_matrix(&doc, text, "D", 4)?;
    let size = [
        size_field(&doc, text, "image_width")?,
        size_field(&doc, text, "image_height")?,
    ];
    if k[0] <= 0.0 || k[4] <= 0.0 {
        return Err(at_key(text, "K", FieldProblem::FocalLength));
    }
    let model = UnifiedModel {
        focal_px: [k[0], k[4]],
        skew_px: k[1],
        principal_px: [k[2], k[5]],
        xi,
        distortion: [d[0], d[1], d[2], d[3]],
    };
    Ok(CameraFile::Unified(model, size))
}

fn parse_kalibr(text: &str, format: &str) -> Result<CameraFile, CameraFileError> {
    let doc = load_yaml(text)?;
    let cam = field(&doc, text, "cam0", FieldProblem::MissingCamera)?;
    let in_cam = || FieldProblem::MissingIn("cam0");
    let model_name = field(cam, text, "camera_model", in_cam())?
        .as_str()
        .unwrap_or_default();
    let want = if format == "kalibr-ds" { "ds" } else { "omni" };
    if model_name != want {
        return Err(at_key(
            text,
            "camera_model",
            FieldProblem::WrongModel {
                found: model_name.to_string(),
                format: format.to_string(),
                needed: want,
            },
        ));
    }
    let res = numbers(
        field(cam, text, "resolution", in_cam())?,
        text,
        "resolution",
        2,
    )?;
    let size = [res[0] as u32, res[1] as u32];
    let (n, n_dist) = if want == "ds" { (6, 0) } else { (5, 4) };
    let p = numbers(
        field(cam, text, "intrinsics", in_cam())?,
        text,
        "intrinsics",
        n,
    )?;
    let dist = match &cam["distortion_coeffs"] {
        Yaml::BadValue if n_dist == 0 => Vec::new(),
        y => numbers(y, text, "distortion_coeffs", n_dist)?,
    };
    Ok(if want == "ds" {
        CameraFile::DoubleSphere(
            DoubleSphereModel {
                focal_px: [p[2], p[3]],
                principal_px: [p[4], p[5]],
                xi: p[0],
                alpha: p[1],
            },
            size,
        )
    } else {
        CameraFile::Unified(
            UnifiedModel {
                focal_px: [p[1], p[2]],
                skew_px: 0.0,
                principal_px: [p[3], p[4]],
                xi: p[0],
                distortion: [dist[0], dist[1], dist[2], dist[3]],
            },
            size,
        )
    })
}

/// `problem` with the field `field` of a `calib_results.txt`, at `line`.
fn at_line(line: usize, field: &'static str, problem: FieldProblem) -> CameraFileError {
    CameraFileError::Field {
        line,
        field,
        problem,
    }
}

/// A `calib_results.txt` line of numbers and its 1-based line.
type NumberLine = (usize, Vec<f64>);

/// The `(count, coefficients...)` line of a polynomial: its coefficients.
fn counted((line, v): NumberLine, field: &'static str) -> Result<Vec<f64>, CameraFileError> {
    let n = v.first().copied().unwrap_or(0.0);
    if n < 1.0 || n.fract() != 0.0 || v.len() != n as usize + 1 {
        return Err(at_line(line, field, FieldProblem::NotCounted));
    }
    Ok(v[1..].to_vec())
}

/// A line of exactly `n` numbers.
fn exact(
    (line, v): NumberLine,
    field: &'static str,
    n: usize,
) -> Result<Vec<f64>, CameraFileError> {
    if v.len() == n {
        Ok(v)
    } else {
        Err(at_line(
            line,
            field,
            FieldProblem::Count {
                expected: n,
                found: v.len(),
            },
        ))
    }
}

/// OCamCalib's `calib_results.txt`: its fields in order, each on the first line with numbers
/// after its comment line.
fn parse_ocamcalib(text: &str) -> Result<CameraFile, CameraFileError> {
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let mut next = |field: &'static str| -> Result<NumberLine, CameraFileError> {
        let (i, l) = lines
            .next()
            .ok_or_else(|| at_line(text.lines().count(), field, FieldProblem::Missing))?;
        let values: Result<Vec<f64>, _> = l.split_whitespace().map(str::parse::<f64>).collect();
        match values {
            Ok(v) if v.iter().all(|x| x.is_finite()) => Ok((i + 1, v)),
            _ => Err(at_line(
                i + 1,
                field,
                FieldProblem::NotNumbers(l.to_string()),
            )),
        }
    };
    let pol_at = next("pol")?;
    let pol_line = pol_at.0;
    let pol = counted(pol_at, "pol")?;
    let invpol = counted(next("invpol")?, "invpol")?;
    let center = exact(next("center")?, "center", 2)?;
    let affine = exact(next("affine")?, "affine", 3)?;
    let (size_line, size) = next("size")?;
    let size = exact((size_line, size), "size", 2)?;
    if size.iter().any(|s| *s < 1.0 || s.fract() != 0.0) {
        return Err(at_line(size_line, "size", FieldProblem::NotPixelSize));
    }
    let [c, d, e] = [affine[0], affine[1], affine[2]];
    if (c - d * e).abs() < 1e-12 {
        return Err(at_line(
            line_of_values(text, 4),
            "affine",
            FieldProblem::NoAffineInverse,
        ));
    }
    let model = OcamModel {
        pol,
        invpol,
        center_rc: [center[0], center[1]],
        affine: [c, d, e],
        size_hw: [size[0] as u32, size[1] as u32],
    };
    model
        .check_polynomial()
        .map_err(|why| at_line(pol_line, "pol", why.into()))?;
    Ok(CameraFile::Ocam(model))
}

/// The 1-based line of the `k`-th (1-based) line of numbers of a `calib_results.txt`.
fn line_of_values(text: &str, k: usize) -> usize {
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .nth(k - 1)
        .map_or(1, |(i, _)| i + 1)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera_model::files::{
        ModelPose, kalibr_ds_yaml, kalibr_omni_yaml, opencv_omnidir_yaml,
    };
    use nalgebra::{Matrix3, Vector3};

    fn unified() -> UnifiedModel {
        UnifiedModel {
            focal_px: [110.7, 110.8],
            skew_px: 0.0,
            principal_px: [127.5, 109.5],
            xi: 0.973,
            distortion: [0.01, -0.002, 0.0003, -0.0004],
        }
    }

    fn pose() -> ModelPose {
        ModelPose {
            rotation: Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0),
            translation_mm: Vector3::new(0.0, 0.0, 205.08),
        }
    }

    #[test]
    fn every_written_file_reads_back_the_same() {
        let m = unified();
        let cv = opencv_omnidir_yaml(&m, [256, 220], &pose(), "a test");
        assert_eq!(
            parse_camera_file(&cv, "opencv-omnidir").unwrap(),
            CameraFile::Unified(m, [256, 220])
        );
        let k = kalibr_omni_yaml(&m, [256, 220], &pose(), "/camera/omni", "");
        assert_eq!(
            parse_camera_file(&k, "kalibr-omni").unwrap(),
            CameraFile::Unified(m, [256, 220])
        );
        let ds = DoubleSphereModel {
            focal_px: [100.0, 101.0],
            principal_px: [127.5, 109.5],
            xi: -0.2,
            alpha: 0.6,
        };
        let k = kalibr_ds_yaml(&ds, [256, 220], &pose(), "/camera/omni", "");
        assert_eq!(
            parse_camera_file(&k, "kalibr-ds").unwrap(),
            CameraFile::DoubleSphere(ds, [256, 220])
        );
        let ocam = OcamModel {
            pol: vec![-56.1, 0.0, 4.4e-3, -1.3e-7, -3.9e-9],
            invpol: vec![113.8, 116.9, 63.2],
            center_rc: [109.5, 127.5],
            affine: [1.0, 0.0, 0.0],
            size_hw: [220, 256],
        };
        let CameraFile::Ocam(back) =
            parse_camera_file(&ocam.calib_results_txt(), "ocamcalib").unwrap()
        else {
            panic!("not an OCamCalib model")
        };
        for (a, b) in back.pol.iter().zip(&ocam.pol) {
            assert!((a - b).abs() <= 1e-11 * b.abs());
        }
        assert_eq!(
            (back.center_rc, back.size_hw),
            (ocam.center_rc, ocam.size_hw)
        );
    }

    #[test]
    fn a_bad_file_names_the_line_and_the_field() {
        let cv = opencv_omnidir_yaml(&unified(), [256, 220], &pose(), "");
        // A missing field: named, with the line where it would be looked for.
        let no_xi = cv.replace("xi: !!opencv-matrix", "chi: !!opencv-matrix");
        let e = parse_camera_file(&no_xi, "opencv-omnidir").unwrap_err();
        assert!(
            matches!(
                e,
                CameraFileError::Field {
                    field: "xi",
                    problem: FieldProblem::Missing,
                    ..
                }
            ),
            "{e:?}"
        );
        let e = e.to_string();
        assert!(e.contains("field `xi`: missing"), "{e}");
        // A short matrix: its line.
        let short = cv.replace("data: [ 0.01, -0.002, 0.0003, -0.0004 ]", "data: [ 0.01 ]");
        let e = parse_camera_file(&short, "opencv-omnidir")
            .unwrap_err()
            .to_string();
        let line = cv.lines().position(|l| l.starts_with("D:")).unwrap() + 1;
        assert!(e.starts_with(&format!("line {line}, field `D`")), "{e}");
        // The wrong format.
        let k = kalibr_omni_yaml(&unified(), [256, 220], &pose(), "/c", "");
        let e = parse_camera_file(&k, "opencv-omnidir")
            .unwrap_err()
            .to_string();
        assert!(e.contains("Kalibr camchain"), "{e}");
        let e = parse_camera_file(&k, "kalibr-ds").unwrap_err().to_string();
        assert!(
            e.contains("field `camera_model`") && e.contains("\"omni\""),
            "{e}"
        );
        // Not YAML at all.
        let e = parse_camera_file("K: [1, 2\n", "opencv-omnidir")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("line 2: not YAML"), "{e}");
        // OCamCalib: a count that does not match its coefficients, a missing field.
        let e = parse_camera_file("#pol\n5 1 2 3\n", "ocamcalib")
            .unwrap_err()
            .to_string();
        assert_eq!(e, "line 2, field `pol`: a count and that many coefficients");
        let e = parse_camera_file("#pol\n2 1 2\n#inv\n1 5\n", "ocamcalib")
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("field `center`: missing"), "{e}");
        // OCamCalib: a polynomial whose rays turn back inside the image.
        let mut bent = OcamModel {
            pol: vec![-56.1, 0.0, 4.4e-3, -1.3e-7, -3.9e-9],
            invpol: vec![113.8, 116.9, 63.2],
            center_rc: [109.5, 127.5],
            affine: [1.0, 0.0, 0.0],
            size_hw: [220, 256],
        };
        assert!(bent.check_polynomial().is_ok());
        bent.pol[4] = -3.0e-7;
        let text = bent.calib_results_txt();
        let e = parse_camera_file(&text, "ocamcalib")
            .unwrap_err()
            .to_string();
        let line = text.lines().position(|l| l.starts_with("5 ")).unwrap() + 1;
        assert!(
            e.starts_with(&format!(
                "line {line}, field `pol`: f(rho) - rho tan(theta) has no real root"
            )),
            "{e}"
        );
        bent.pol[0] = 0.0;
        let e = parse_camera_file(&bent.calib_results_txt(), "ocamcalib")
            .unwrap_err()
            .to_string();
        assert!(e.ends_with("a0 is 0: the image centre has no ray"), "{e}");
        let e = parse_camera_file("", "kalibr-dss").unwrap_err().to_string();
        assert!(e.contains("unknown camera model format"), "{e}");
    }
}
