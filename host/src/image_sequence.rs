//! Stereo image sequences on disk: a directory per camera, files paired by sorted name,
//! PNG / PGM / JPEG, colour converted to 8-bit grey.
//!
//! Everything that can be checked before the first frame is processed (directories exist, hold
//! images, the same number of them) is checked in `open`, so a bad invocation fails at once and
//! writes nothing; each pair is decoded only when it is needed.

use std::path::{Path, PathBuf};

/// An 8-bit grey image, row-major.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GrayFrame {
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// `width·height` grey levels, row-major from the top-left pixel.
    pub pixels: Vec<u8>,
}

/// A stereo sequence that cannot be read, naming the directory, file or frame at fault.
#[derive(Debug, thiserror::Error)]
pub enum SequenceError {
    /// A camera's directory does not exist or is not a directory.
    #[error("{camera} image directory {path} does not exist or is not a directory")]
    MissingDir {
        /// `left` or `right`.
        camera: &'static str,
        /// The directory.
        path: PathBuf,
    },
    /// A camera's directory could not be listed.
    #[error("{camera} image directory {path} cannot be listed: {source}")]
    ListDir {
        /// `left` or `right`.
        camera: &'static str,
        /// The directory.
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A camera's directory holds no image file.
    #[error("{camera} image directory {path} holds no .png, .pgm, .jpg or .jpeg files")]
    Empty {
        /// `left` or `right`.
        camera: &'static str,
        /// The directory.
        path: PathBuf,
    },
    /// The two directories hold different numbers of images.
    #[error("left directory has {left} images but right directory has {right}; frames are paired by sorted name")]
    CountMismatch {
        /// Images in the left directory.
        left: usize,
        /// Images in the right directory.
        right: usize,
    },
    /// An image file could not be read or decoded.
    #[error("{path}: cannot decode image: {source}")]
    Decode {
        /// The file.
        path: PathBuf,
        /// The `image` crate's error (a read error as its `IoError`).
        source: image::ImageError,
    },
    /// The two images of a pair differ in size.
    #[error("frame {frame}: left image {left_w}x{left_h} and right image {right_w}x{right_h} differ in size")]
    PairSize {
        /// 0-based index of the pair.
        frame: usize,
        /// Left image width in pixels.
        left_w: usize,
        /// Left image height in pixels.
        left_h: usize,
        /// Right image width in pixels.
        right_w: usize,
        /// Right image height in pixels.
        right_h: usize,
    },
    /// A pair's size differs from the first pair's.
    #[error("frame {frame}: image size {width}x{height} differs from the first frame's {first_w}x{first_h}")]
    SizeChanged {
        /// 0-based index of the pair.
        frame: usize,
        /// Its width in pixels.
        width: usize,
        /// Its height in pixels.
        height: usize,
        /// The first pair's width in pixels.
        first_w: usize,
        /// The first pair's height in pixels.
        first_h: usize,
    },
    /// The images are wider than the fabric's line buffers.
    #[error(
        "frame {frame}: image is {width} px wide; the fabric's line buffers hold at most {max} px"
    )]
    TooWide {
        /// 0-based index of the pair.
        frame: usize,
        /// Its width in pixels.
        width: usize,
        /// [`SizeLimits::max_width`].
        max: usize,
    },
    /// A side of the images is shorter than the pyramid needs.
    #[error("frame {frame}: image is {width}x{height}; the pyramid needs at least {min}x{min}")]
    TooSmall {
        /// 0-based index of the pair.
        frame: usize,
        /// Its width in pixels.
        width: usize,
        /// Its height in pixels.
        height: usize,
        /// [`SizeLimits::min_side`].
        min: usize,
    },
}

impl GrayFrame {
    /// The top-left `width` x `height` window (the origin stays, so the intrinsics still
    /// hold); `None` when the window is larger than the frame. A frame that is the window
    /// already is returned as it is, and the rows of a smaller one move in place, so a pair
    /// costs no copy on its way to the device.
    pub fn cropped(mut self, width: usize, height: usize) -> Option<GrayFrame> {
        if width > self.width || height > self.height {
            return None;
        }
        if width != self.width {
            for row in 1..height {
                let from = row * self.width;
                self.pixels.copy_within(from..from + width, row * width);
            }
        }
        self.pixels.truncate(width * height);
        self.width = width;
        self.height = height;
        Some(self)
    }
}

/// Limits the fabric puts on the image size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SizeLimits {
    /// Widest image in pixels: the length of the fabric's line buffers.
    pub max_width: usize,
    /// Shortest side in pixels that the pyramid accepts.
    pub min_side: usize,
}

impl SizeLimits {
    /// The limits of the fabric's registers (`regmap.toml`): what a session can be
    /// configured for.
    pub fn fabric() -> Self {
        Self {
            max_width: stereocal_hdl::regs::MAX_WIDTH as usize,
            min_side: stereocal_hdl::regs::MIN_SIDE as usize,
        }
    }
}

/// The file names of a stereo sequence, checked and paired.
#[derive(Debug, Clone)]
pub struct StereoSequence {
    left: Vec<PathBuf>,
    right: Vec<PathBuf>,
    limits: SizeLimits,
}

impl StereoSequence {
    /// Lists and pairs the two directories.
    pub fn open(left: &Path, right: &Path, limits: SizeLimits) -> Result<Self, SequenceError> {
        let left = list_images("left", left)?;
        let right = list_images("right", right)?;
        if left.len() != right.len() {
            return Err(SequenceError::CountMismatch {
                left: left.len(),
                right: right.len(),
            });
        }
        Ok(StereoSequence {
            left,
            right,
            limits,
        })
    }

    /// Number of frame pairs.
    pub fn len(&self) -> usize {
        self.left.len()
    }

    /// Always false once `open` succeeded; present for API completeness with `len`.
    pub fn is_empty(&self) -> bool {
        self.left.is_empty()
    }

    /// Decodes pair `frame`, checking it against the limits and against `first` (the size of
    /// frame 0, once known).
    pub fn pair(
        &self,
        frame: usize,
        first: Option<(usize, usize)>,
    ) -> Result<(GrayFrame, GrayFrame), SequenceError> {
        let l = load_gray(&self.left[frame])?;
        let r = load_gray(&self.right[frame])?;
        if (l.width, l.height) != (r.width, r.height) {
            return Err(SequenceError::PairSize {
                frame,
                left_w: l.width,
                left_h: l.height,
                right_w: r.width,
                right_h: r.height,
            });
        }
        if let Some((first_w, first_h)) = first {
            if (l.width, l.height) != (first_w, first_h) {
                return Err(SequenceError::SizeChanged {
                    frame,
                    width: l.width,
                    height: l.height,
                    first_w,
                    first_h,
                });
            }
        }
        if l.width > self.limits.max_width {
            return Err(SequenceError::TooWide {
                frame,
                width: l.width,
                max: self.limits.max_width,
            });
        }
        if l.width < self.limits.min_side || l.height < self.limits.min_side {
            return Err(SequenceError::TooSmall {
                frame,
                width: l.width,
                height: l.height,
                min: self.limits.min_side,
            });
        }
        Ok((l, r))
    }
}

fn list_images(camera: &'static str, dir: &Path) -> Result<Vec<PathBuf>, SequenceError> {
    if !dir.is_dir() {
        return Err(SequenceError::MissingDir {
            camera,
            path: dir.to_owned(),
        });
    }
    let entries = std::fs::read_dir(dir).map_err(|source| SequenceError::ListDir {
        camera,
        path: dir.to_owned(),
        source,
    })?;
    let mut files = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|source| SequenceError::ListDir {
            camera,
            path: dir.to_owned(),
            source,
        })?;
        let path = entry.path();
        let is_image = path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| {
                matches!(
                    e.to_ascii_lowercase().as_str(),
                    "png" | "pgm" | "jpg" | "jpeg"
                )
            })
            .unwrap_or(false);
        if is_image && path.is_file() {
            files.push(path);
        }
    }
    if files.is_empty() {
        return Err(SequenceError::Empty {
            camera,
            path: dir.to_owned(),
        });
    }
    files.sort();
    Ok(files)
}

/// Decodes one image file to 8-bit grey (colour by the `image` crate's luma conversion).
pub fn load_gray(path: &Path) -> Result<GrayFrame, SequenceError> {
    let bytes = std::fs::read(path).map_err(|e| SequenceError::Decode {
        path: path.to_owned(),
        source: image::ImageError::IoError(e),
    })?;
    decode_gray(&bytes, path)
}

/// Decodes an image held in memory exactly as [`load_gray`] decodes the file at
/// `path_for_errors`: the format comes from the content when it is recognisable, else from the
/// path's extension, and every error names `path_for_errors`. The fuzz target `image` drives it.
pub fn decode_gray(bytes: &[u8], path_for_errors: &Path) -> Result<GrayFrame, SequenceError> {
    let err = |source| SequenceError::Decode {
        path: path_for_errors.to_owned(),
        source,
    };
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes));
    // As `ImageReader::open` does: the extension names the format unless the content does.
    let ext = path_for_errors.extension().filter(|ext| !ext.is_empty());
    if let Some(format) = ext.and_then(image::ImageFormat::from_extension) {
        reader.set_format(format);
    }
    let reader = reader
        .with_guessed_format()
        .map_err(|e| err(image::ImageError::IoError(e)))?;
    if reader.format().is_none() {
        if let Some(ext) = ext {
            // The error `ImageReader::open(..).decode()` gives for an unknown extension.
            return Err(err(image::ImageError::Unsupported(
                image::error::ImageFormatHint::PathExtension(ext.into()).into(),
            )));
        }
    }
    let img = reader.decode().map_err(err)?.into_luma8();
    Ok(GrayFrame {
        width: img.width() as usize,
        height: img.height() as usize,
        pixels: img.into_raw(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cropping_keeps_the_top_left_window() {
        let frame = |w: usize, h: usize| GrayFrame {
            width: w,
            height: h,
            pixels: (0..w * h).map(|i| (i % 251) as u8).collect(),
        };
        let window = frame(5, 4).cropped(3, 2).unwrap();
        assert_eq!((window.width, window.height), (3, 2));
        assert_eq!(window.pixels, [0, 1, 2, 5, 6, 7]);
        assert_eq!(frame(5, 4).cropped(5, 4), Some(frame(5, 4)));
        assert_eq!(
            frame(5, 4).cropped(5, 3).unwrap().pixels,
            frame(5, 3).pixels
        );
        assert_eq!(frame(5, 4).cropped(6, 4), None);
        assert_eq!(frame(5, 4).cropped(5, 5), None);
    }

    const LIMITS: SizeLimits = SizeLimits {
        max_width: 64,
        min_side: 8,
    };

    fn write_png(path: &Path, w: u32, h: u32) {
        image::GrayImage::from_fn(w, h, |x, y| image::Luma([(x * 7 + y * 3) as u8]))
            .save(path)
            .unwrap();
    }

    fn dirs() -> (tempfile::TempDir, PathBuf, PathBuf) {
        let root = tempfile::tempdir().unwrap();
        let l = root.path().join("left");
        let r = root.path().join("right");
        std::fs::create_dir(&l).unwrap();
        std::fs::create_dir(&r).unwrap();
        (root, l, r)
    }

    #[test]
    fn pairs_by_sorted_name_and_checks_sizes() {
        let (_root, l, r) = dirs();
        for name in ["b.png", "a.png"] {
            write_png(&l.join(name), 32, 16);
            write_png(&r.join(name), 32, 16);
        }
        write_png(&r.join("a.png"), 32, 17);
        let seq = StereoSequence::open(&l, &r, LIMITS).unwrap();
        assert_eq!(seq.len(), 2);
        assert!(matches!(
            seq.pair(0, None),
            Err(SequenceError::PairSize { frame: 0, .. })
        ));
        let (a, _) = seq.pair(1, None).unwrap();
        assert_eq!((a.width, a.height), (32, 16));
        assert!(matches!(
            seq.pair(1, Some((30, 16))),
            Err(SequenceError::SizeChanged { frame: 1, .. })
        ));
    }

    #[test]
    fn rejects_missing_empty_uneven_wide_and_broken() {
        let (root, l, r) = dirs();
        let missing = root.path().join("nope");
        assert!(matches!(
            StereoSequence::open(&missing, &r, LIMITS),
            Err(SequenceError::MissingDir { camera: "left", .. })
        ));
        assert!(matches!(
            StereoSequence::open(&l, &r, LIMITS),
            Err(SequenceError::Empty { camera: "left", .. })
        ));
        write_png(&l.join("0.png"), 100, 16);
        write_png(&l.join("1.png"), 100, 16);
        write_png(&r.join("0.png"), 100, 16);
        assert!(matches!(
            StereoSequence::open(&l, &r, LIMITS),
            Err(SequenceError::CountMismatch { left: 2, right: 1 })
        ));
        std::fs::write(r.join("1.png"), b"\x89PNG\r\n\x1a\ntruncated").unwrap();
        let seq = StereoSequence::open(&l, &r, LIMITS).unwrap();
        assert!(matches!(
            seq.pair(0, None),
            Err(SequenceError::TooWide { max: 64, .. })
        ));
        let err = seq.pair(1, None).unwrap_err().to_string();
        assert!(err.contains("1.png"), "{err}");
    }
}
