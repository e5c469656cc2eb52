//! Which tool wrote a calibration file, recognised by its content: users name their files as
//! they like (`stereo.yml`, `camchain-imucam.yaml`, `calib.txt`), so extensions say nothing.

/// The calibration formats `--calib` reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// The project's own TOML.
    Toml,
    /// `cv::FileStorage` YAML or JSON with `stereoCalibrate`'s K1, D1, K2, D2, R, T.
    OpenCv,
    /// `cv::FileStorage` XML, which is recognised only to say so.
    OpenCvXml,
    /// Kalibr's `camchain.yaml` (`cam0`, `cam1` with `T_cn_cnm1`).
    Kalibr,
    /// KITTI's `calib.txt` (`P0:` … `P3:`) or raw-data `calib_cam_to_cam.txt` (`P_rect_00:` …).
    Kitti,
}

impl Format {
    /// Recognises the format by marks no other of them has: `<opencv_storage>` (OpenCV XML),
    /// `%YAML:1.0` or an `opencv-matrix` type (OpenCV YAML, JSON), a top-level `cam0:`
    /// (Kalibr), a line starting `P0:` or `P_rect_00:` (KITTI). None of these is valid TOML,
    /// so everything else is TOML.
    pub fn detect(text: &str) -> Self {
        let text = text.trim_start_matches('\u{feff}');
        if text.contains("<opencv_storage>") {
            return Self::OpenCvXml;
        }
        let opencv_matrix = text
            .lines()
            .any(|l| !l.trim_start().starts_with('#') && l.contains("opencv-matrix"));
        if text.trim_start().starts_with("%YAML:") || opencv_matrix {
            return Self::OpenCv;
        }
        let starts = |prefix: &str| text.lines().any(|l| l.starts_with(prefix));
        if starts("cam0:") {
            Self::Kalibr
        } else if starts("P0:") || starts("P_rect_00:") {
            Self::Kitti
        } else {
            Self::Toml
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_tool_is_recognised_by_its_marks() {
        assert_eq!(
            Format::detect("%YAML:1.0\n---\nK1: !!opencv-matrix\n"),
            Format::OpenCv
        );
        assert_eq!(
            Format::detect("R: !!opencv-matrix\n   rows: 3\n"),
            Format::OpenCv
        );
        assert_eq!(
            Format::detect("{\n    \"R\": {\n        \"type_id\": \"opencv-matrix\",\n"),
            Format::OpenCv
        );
        assert_eq!(
            Format::detect(
                "<?xml version=\"1.0\"?>\n<opencv_storage>\n<R type_id=\"opencv-matrix\">"
            ),
            Format::OpenCvXml
        );
        assert_eq!(
            Format::detect("cam0:\n  camera_model: pinhole\ncam1:\n"),
            Format::Kalibr
        );
        assert_eq!(Format::detect("P0: 7.0e+02 0 0\nP1: 1 2\n"), Format::Kitti);
        assert_eq!(
            Format::detect("calib_time: 09-Jan-2012\nP_rect_00: 7.2e+02\n"),
            Format::Kitti
        );
        assert_eq!(Format::detect("baseline_m = 0.3\n[left]\n"), Format::Toml);
        // A TOML comment that mentions a mark is still TOML.
        assert_eq!(
            Format::detect("# cam0: P0: !!opencv-matrix\nbaseline_m = 0.3\n"),
            Format::Toml
        );
    }
}
