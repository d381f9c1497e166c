//! ROS 2 bags (MCAP) as a frame source: the images of one topic, `sensor_msgs/msg/Image`
//! (`mono8`, `rgb8`, `bgr8`, `rgba8`, `bgra8`, and `mono16` scaled to 8 bits by its high byte)
//! or `sensor_msgs/msg/CompressedImage` (JPEG, PNG), turned into grey frames with the
//! workspace's one BT.601 luma ([`grey_frame::luma_bt601`]). The time of a frame is its message
//! header's stamp. Without `--topic`, the bag's only image topic is read; with none or several,
//! the error lists the topics. A message that cannot be decoded (bad CDR, unknown pixel
//! encoding, data shorter than the image) is reported and skipped ([`LaneIoError::BadFrame`]);
//! a damaged container (truncated, bad CRC) ends the run with an error after the last good frame.

use grey_frame::{GreyFrame, luma_bt601};
use ros_bag::bag::{TopicReader, choose_topic, topics};
use ros_bag::msgs::{COMPRESSED_IMAGE, CompressedImage, IMAGE, Image};

use crate::BagImageProblem;
use crate::LaneIoError;
use crate::frame::{FrameMeta, FrameSource};

/// True when `path` has the `.mcap` extension.
pub fn is_mcap(path: &std::path::Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mcap"))
}

/// The images of one topic of a bag.
#[derive(Debug)]
pub struct McapImageSource {
    reader: TopicReader,
    index: u64,
    rgb: Vec<u8>,
}

fn bag_err(source: ros_bag::BagError) -> LaneIoError {
    LaneIoError::Bag { source }
}

impl McapImageSource {
    /// Opens `path` for the image topic `topic` (or its only image topic).
    ///
    /// # Errors
    /// [`LaneIoError::Bag`]: the file cannot be read, or no / several / no such image topic (the
    /// error lists the topics), or the topic is not CDR.
    pub fn open(path: &std::path::Path, topic: Option<&str>) -> Result<Self, LaneIoError> {
        let name = path.display().to_string();
        let all = topics(&name).map_err(bag_err)?;
        let chosen = choose_topic(&name, &all, topic, &[IMAGE, COMPRESSED_IMAGE], "image")
            .map_err(bag_err)?;
        Ok(Self {
            reader: TopicReader::open(&name, chosen).map_err(bag_err)?,
            index: 0,
            rgb: Vec::new(),
        })
    }

    fn bad(&self, frame: u64, problem: BagImageProblem) -> LaneIoError {
        LaneIoError::BadFrame {
            name: self.reader.path().to_owned(),
            frame,
            source: Box::new(LaneIoError::BagImage {
                topic: self.reader.topic().topic.clone(),
                problem,
            }),
        }
    }
}

/// Fills `frame` from an uncompressed image.
fn from_image(img: &Image<'_>, frame: &mut GreyFrame) -> Result<(), BagImageProblem> {
    let (w, h, step) = (img.width as usize, img.height as usize, img.step as usize);
    let bpp = match img.encoding {
        "mono8" | "8UC1" => 1,
        "mono16" | "16UC1" => 2,
        "rgb8" | "bgr8" => 3,
        "rgba8" | "bgra8" => 4,
        other => {
            return Err(BagImageProblem::PixelEncoding {
                encoding: other.to_owned(),
            });
        }
    };
    if w == 0 || h == 0 {
        return Err(BagImageProblem::ZeroSize {
            width_px: w,
            height_px: h,
        });
    }
    // The bytes the rows need; where that overflows usize (a 32-bit target: sizes are u32), the
    // data is short too.
    let needed = step.checked_mul(h - 1).and_then(|n| n.checked_add(w * bpp));
    if step < w * bpp || needed.is_none_or(|n| img.data.len() < n) {
        return Err(BagImageProblem::ShortData {
            len: img.data.len(),
            width_px: w,
            height_px: h,
            encoding: img.encoding.to_owned(),
            step,
        });
    }
    frame.reshape(w, h).map_err(BagImageProblem::FrameBuffer)?;
    let out = frame.data_mut();
    for (r, row_out) in out.chunks_exact_mut(w).enumerate() {
        let row = &img.data[r * step..r * step + w * bpp];
        match img.encoding {
            "mono8" | "8UC1" => row_out.copy_from_slice(row),
            "mono16" | "16UC1" => {
                for (o, p) in row_out.iter_mut().zip(row.chunks_exact(2)) {
                    *o = if img.is_bigendian != 0 { p[0] } else { p[1] };
                }
            }
            "rgb8" | "rgba8" => {
                for (o, p) in row_out.iter_mut().zip(row.chunks_exact(bpp)) {
                    *o = luma_bt601(p[0], p[1], p[2]);
                }
            }
            _ => {
                for (o, p) in row_out.iter_mut().zip(row.chunks_exact(bpp)) {
                    *o = luma_bt601(p[2], p[1], p[0]);
                }
            }
        }
    }
    Ok(())
}

/// Fills `frame` from a JPEG or PNG.
fn from_compressed(
    img: &CompressedImage<'_>,
    frame: &mut GreyFrame,
    rgb: &mut Vec<u8>,
) -> Result<(), BagImageProblem> {
    let f = img.format.to_ascii_lowercase();
    let format = if f.contains("png") {
        image::ImageFormat::Png
    } else if f.contains("jpeg") || f.contains("jpg") {
        image::ImageFormat::Jpeg
    } else {
        return Err(BagImageProblem::CompressedFormat {
            format: img.format.to_owned(),
        });
    };
    let decoded =
        image::load_from_memory_with_format(img.data, format).map_err(BagImageProblem::Decode)?;
    let (w, h) = (decoded.width() as usize, decoded.height() as usize);
    frame.reshape(w, h).map_err(BagImageProblem::FrameBuffer)?;
    match decoded {
        image::DynamicImage::ImageLuma8(g) => frame.data_mut().copy_from_slice(g.as_raw()),
        other => {
            rgb.clear();
            rgb.extend_from_slice(other.to_rgb8().as_raw());
            for (o, p) in frame.data_mut().iter_mut().zip(rgb.chunks_exact(3)) {
                *o = luma_bt601(p[0], p[1], p[2]);
            }
        }
    }
    Ok(())
}

impl FrameSource for McapImageSource {
    fn next_frame(&mut self, frame: &mut GreyFrame) -> Result<Option<FrameMeta>, LaneIoError> {
        let Some(msg) = self.reader.next_message().map_err(bag_err)? else {
            return Ok(None);
        };
        let index = self.index;
        self.index += 1;
        let decoded = if msg.schema == IMAGE {
            Image::decode(msg.data)
                .map_err(BagImageProblem::from)
                .and_then(|img| {
                    from_image(&img, frame)?;
                    Ok(img.header.t_s())
                })
        } else {
            CompressedImage::decode(msg.data)
                .map_err(BagImageProblem::from)
                .and_then(|img| {
                    from_compressed(&img, frame, &mut self.rgb)?;
                    Ok(img.header.t_s())
                })
        };
        match decoded {
            Ok(t_s) => Ok(Some(FrameMeta { index, t_s })),
            Err(what) => Err(self.bad(index, what)),
        }
    }

    fn describe(&self) -> String {
        let t = self.reader.topic();
        format!(
            "{} (MCAP, topic {} of {})",
            self.reader.path(),
            t.topic,
            t.schema
        )
    }
}
