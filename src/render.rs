//! PNG images of the height map and the cost layers, for people (paper Fig. 3).
//!
//! Every image is 8-bit RGB, one pixel per cell, with +x to the right and +y **up**: image
//! row `r` (top to bottom) shows cell row `j = ny − 1 − r`.
//!
//! Colours:
//! - cost layers: finite costs on a logarithmic scale from `1` (dark blue, 20 20 90)
//!   through teal (0 150 190) to `max_cost` and above (magenta, 220 50 180), where `t =
//!   ln(C) / ln(max_cost)` is interpolated linearly between the three stops (costs below
//!   1 are drawn as 1); **infinite** = yellow (255 230 0) "not traversable", **unknown** =
//!   olive (128 128 0), as in the paper's Fig. 3;
//! - height: grey from black (lowest known height) to white (highest), unknown = olive.

use std::path::{Path, PathBuf};

use crate::cost::{Cost, CostMaps};
use crate::terrain::HeightMap;

/// Colour of infinite ("not traversable") cells.
pub const INFINITE_RGB: [u8; 3] = [255, 230, 0];
/// Colour of unknown cells.
pub const UNKNOWN_RGB: [u8; 3] = [128, 128, 0];
const STOPS: [[f64; 3]; 3] = [[20.0, 20.0, 90.0], [0.0, 150.0, 190.0], [220.0, 50.0, 180.0]];

/// Why an image could not be written.
#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    /// Creating or writing the file failed.
    #[error("cannot write image {path}: {source}")]
    Io {
        /// The image path.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// PNG encoding failed.
    #[error("cannot encode PNG {path}: {source}")]
    Encode {
        /// The image path.
        path: PathBuf,
        /// The cause.
        source: png::EncodingError,
    },
    /// The layer does not match its stated dimensions, or is too large for PNG.
    #[error(
        "cannot write image {path}: layer of {len} values is not {nx} x {ny} (or exceeds PNG limits)"
    )]
    BadLayer {
        /// The image path.
        path: PathBuf,
        /// Values given.
        len: usize,
        /// Columns.
        nx: usize,
        /// Rows.
        ny: usize,
    },
}

/// The colour of a cost with the module's scale (`max_cost` > 1 sets the top of the
/// scale; smaller values are treated as 2).
pub fn cost_colour(c: Cost, max_cost: f64) -> [u8; 3] {
    match c {
        Cost::Infinite => INFINITE_RGB,
        Cost::Unknown => UNKNOWN_RGB,
        Cost::Finite(v) => {
            let top = if max_cost.is_finite() && max_cost > 1.0 { max_cost } else { 2.0 };
            let t = (v.max(1.0).ln() / top.ln()).clamp(0.0, 1.0);
            let (a, b, u) = if t < 0.5 {
                (STOPS[0], STOPS[1], t * 2.0)
            } else {
                (STOPS[1], STOPS[2], t * 2.0 - 1.0)
            };
            [0, 1, 2].map(|k| (a[k] + (b[k] - a[k]) * u).round().clamp(0.0, 255.0) as u8)
        }
    }
}

/// Writes a row-major cost layer (`nx × ny`) with `max_cost` at the top of the scale; with
/// `None`, the largest finite value in the layer.
///
/// # Errors
/// Wrong layer length, or the file cannot be written.
pub fn write_cost_layer_png(
    costs: &[Cost],
    nx: usize,
    ny: usize,
    max_cost: Option<f64>,
    path: &Path,
) -> Result<(), ImageError> {
    let bad = || ImageError::BadLayer { path: path.to_path_buf(), len: costs.len(), nx, ny };
    write_png(&cost_layer_image(costs, nx, ny, max_cost).ok_or_else(bad)?, path)
}

/// An 8-bit RGB picture of a layer, rows top to bottom (+y up), ready for a PNG or a
/// Rerun image.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RgbImage {
    /// Columns (cells along x).
    pub width: u32,
    /// Rows (cells along y).
    pub height: u32,
    /// `width · height · 3` bytes.
    pub pixels: Vec<u8>,
}

/// A row-major cost layer (`nx × ny`) in the module's colours, `max_cost` at the top of the
/// scale (with `None`, the largest finite value); `None` if the layer is not `nx × ny`.
pub fn cost_layer_image(
    costs: &[Cost],
    nx: usize,
    ny: usize,
    max_cost: Option<f64>,
) -> Option<RgbImage> {
    let top =
        max_cost.unwrap_or_else(|| costs.iter().filter_map(|c| c.finite()).fold(1.0, f64::max));
    render(nx, ny, costs.len(), |k| cost_colour(costs[k], top))
}

/// The height map in grey (lowest known height black, highest white), unknown olive.
pub fn height_image(map: &HeightMap) -> Option<RgbImage> {
    let (nx, ny) = map.dims();
    render(nx, ny, map.len(), height_colour(map))
}

/// The colour of [`height_image`] for each row-major cell of `map`.
fn height_colour(map: &HeightMap) -> impl Fn(usize) -> [u8; 3] + '_ {
    let v = map.as_slice();
    let (lo, hi) = v
        .iter()
        .filter(|h| !h.is_nan())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &h| (lo.min(h), hi.max(h)));
    let span = if hi > lo { hi - lo } else { 1.0 };
    move |k| {
        if v[k].is_nan() {
            UNKNOWN_RGB
        } else {
            let g = ((v[k] - lo) / span * 255.0).round().clamp(0.0, 255.0) as u8;
            [g, g, g]
        }
    }
}

/// Where a search went: the height map in dim grey (unknown olive), and every cell whose
/// base poses the search expanded (`counts`, row-major `nx × ny`, expansions per cell) in
/// the cost scale's colours, from 1 expansion (dark blue) to the most expanded cell
/// (magenta) on a logarithmic scale. `None` if `counts` is not the map's size.
pub fn expansion_image(map: &HeightMap, counts: &[u32]) -> Option<RgbImage> {
    let (nx, ny) = map.dims();
    let grey = height_colour(map);
    let top = f64::from(counts.iter().copied().max().unwrap_or(0)).max(2.0);
    render(nx, ny, counts.len(), |k| {
        if counts[k] > 0 {
            cost_colour(Cost::Finite(f64::from(counts[k])), top)
        } else {
            match grey(k) {
                UNKNOWN_RGB => UNKNOWN_RGB,
                c => c.map(|v| v / 2),
            }
        }
    })
}

/// Writes [`expansion_image`].
///
/// # Errors
/// `counts` is not the map's size, or the file cannot be written.
pub fn write_expansion_png(map: &HeightMap, counts: &[u32], path: &Path) -> Result<(), ImageError> {
    let (nx, ny) = map.dims();
    let bad = || ImageError::BadLayer { path: path.to_path_buf(), len: counts.len(), nx, ny };
    write_png(&expansion_image(map, counts).ok_or_else(bad)?, path)
}

/// Writes the height map in grey, unknown cells olive.
///
/// # Errors
/// The file cannot be written.
pub fn write_height_png(map: &HeightMap, path: &Path) -> Result<(), ImageError> {
    let (nx, ny) = map.dims();
    let bad = || ImageError::BadLayer { path: path.to_path_buf(), len: map.len(), nx, ny };
    write_png(&height_image(map).ok_or_else(bad)?, path)
}

/// Writes the foot-cost layer C_F (eq. 1).
///
/// # Errors
/// The file cannot be written.
pub fn write_foot_cost_png(
    maps: &CostMaps,
    max_cost: Option<f64>,
    path: &Path,
) -> Result<(), ImageError> {
    let (nx, ny) = maps.heights().dims();
    let costs: Vec<Cost> = (0..nx * ny).map(|k| maps.foot_cost_cell(k % nx, k / nx)).collect();
    write_cost_layer_png(&costs, nx, ny, max_cost, path)
}

/// Writes the body cost C_B (eq. 3) of a base centred on each cell with orientation
/// `theta`, neutral footprint, all legs at `leg_height` (paper Fig. 3c).
///
/// # Errors
/// The file cannot be written.
pub fn write_body_cost_png(
    maps: &CostMaps,
    theta: f64,
    leg_height: f64,
    max_cost: Option<f64>,
    path: &Path,
) -> Result<(), ImageError> {
    let (nx, ny) = maps.heights().dims();
    write_cost_layer_png(&maps.body_cost_layer(theta, leg_height), nx, ny, max_cost, path)
}

/// Writes the pose cost C (eq. 4) of a base centred on each cell with orientation
/// `theta`, neutral footprint, all legs at `leg_height` (paper Fig. 3d).
///
/// # Errors
/// The file cannot be written.
pub fn write_pose_cost_png(
    maps: &CostMaps,
    theta: f64,
    leg_height: f64,
    max_cost: Option<f64>,
    path: &Path,
) -> Result<(), ImageError> {
    let (nx, ny) = maps.heights().dims();
    write_cost_layer_png(&maps.pose_cost_layer(theta, leg_height), nx, ny, max_cost, path)
}

fn render(nx: usize, ny: usize, len: usize, colour: impl Fn(usize) -> [u8; 3]) -> Option<RgbImage> {
    let (w, h) = (u32::try_from(nx).ok()?, u32::try_from(ny).ok()?);
    if nx == 0 || ny == 0 || nx.checked_mul(ny) != Some(len) {
        return None;
    }
    let mut pixels = Vec::with_capacity(len * 3);
    for r in 0..ny {
        let j = ny - 1 - r;
        for i in 0..nx {
            pixels.extend_from_slice(&colour(j * nx + i));
        }
    }
    Some(RgbImage { width: w, height: h, pixels })
}

/// Writes an image as an 8-bit RGB PNG.
///
/// # Errors
/// The file cannot be created or encoded.
pub fn write_png(image: &RgbImage, path: &Path) -> Result<(), ImageError> {
    let io = |source| ImageError::Io { path: path.to_path_buf(), source };
    let enc = |source| ImageError::Encode { path: path.to_path_buf(), source };
    let file = std::fs::File::create(path).map_err(io)?;
    let mut encoder = png::Encoder::new(std::io::BufWriter::new(file), image.width, image.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(enc)?;
    writer.write_image_data(&image.pixels).map_err(enc)?;
    writer.finish().map_err(enc)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;
    use crate::robot::RobotDescription;
    use crate::scenario::terrain::{Pole, Primitive, Ramp};
    use crate::terrain::rasterise;

    fn read_png(path: &Path) -> (u32, u32, Vec<u8>) {
        let decoder =
            png::Decoder::new(std::io::BufReader::new(std::fs::File::open(path).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        assert_eq!(info.color_type, png::ColorType::Rgb);
        (info.width, info.height, buf)
    }

    fn tmp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("momaro-cost-image-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    #[test]
    fn scale_endpoints_and_special_colours() {
        assert_eq!(cost_colour(Cost::Finite(1.0), 100.0), [20, 20, 90]);
        assert_eq!(cost_colour(Cost::Finite(10.0), 100.0), [0, 150, 190]);
        assert_eq!(cost_colour(Cost::Finite(1e6), 100.0), [220, 50, 180]);
        assert_eq!(cost_colour(Cost::Infinite, 100.0), INFINITE_RGB);
        assert_eq!(cost_colour(Cost::Unknown, 100.0), UNKNOWN_RGB);
        assert_ne!(INFINITE_RGB, UNKNOWN_RGB);
    }

    #[test]
    fn layer_is_written_with_y_up() {
        // 3 x 2: bottom-left cell (0, 0) infinite, top-right (2, 1) unknown.
        let mut costs = vec![Cost::Finite(1.0); 6];
        costs[0] = Cost::Infinite;
        costs[5] = Cost::Unknown;
        let p = tmp("layer.png");
        write_cost_layer_png(&costs, 3, 2, None, &p).unwrap();
        let (w, h, buf) = read_png(&p);
        assert_eq!((w, h), (3, 2));
        let px = |r: usize, c: usize| {
            [buf[(r * 3 + c) * 3], buf[(r * 3 + c) * 3 + 1], buf[(r * 3 + c) * 3 + 2]]
        };
        assert_eq!(px(1, 0), INFINITE_RGB, "cell (0,0) is bottom-left");
        assert_eq!(px(0, 2), UNKNOWN_RGB, "cell (2,1) is top-right");
        assert_eq!(px(0, 0), [20, 20, 90]);
    }

    #[test]
    fn expansions_are_drawn_over_the_dimmed_height_map() {
        // 3 x 2 cells: heights 0 except (2, 0) at 1 m (white, dimmed to 127) and (0, 1)
        // unknown; the search expanded (0, 0) once, (1, 0) 10 times, (1, 1) 100 times.
        let mut m = HeightMap::filled([0.0, 0.0], 0.025, 3, 2, 0.0).unwrap();
        m.set(2, 0, 1.0).unwrap();
        m.set(0, 1, f64::NAN).unwrap();
        let counts = [1, 10, 0, 0, 100, 0];
        let p = tmp("expansions.png");
        write_expansion_png(&m, &counts, &p).unwrap();
        let (w, h, buf) = read_png(&p);
        assert_eq!((w, h), (3, 2));
        let px = |r: usize, c: usize| {
            [buf[(r * 3 + c) * 3], buf[(r * 3 + c) * 3 + 1], buf[(r * 3 + c) * 3 + 2]]
        };
        // Log scale up to the most expanded cell: 1 → dark blue, √100 = 10 → teal,
        // 100 → magenta (rows top to bottom are y = 1, then y = 0).
        assert_eq!(px(1, 0), [20, 20, 90]);
        assert_eq!(px(1, 1), [0, 150, 190]);
        assert_eq!(px(0, 1), [220, 50, 180]);
        // Not expanded: the height map's grey at half brightness, unknown olive.
        assert_eq!(px(1, 2), [127, 127, 127]);
        assert_eq!(px(0, 2), [0, 0, 0]);
        assert_eq!(px(0, 0), UNKNOWN_RGB);
        // A count layer not the map's size names the file.
        let e = write_expansion_png(&m, &counts[..5], &p).unwrap_err();
        assert!(matches!(e, ImageError::BadLayer { len: 5, nx: 3, ny: 2, .. }), "{e}");
    }

    #[test]
    fn errors_name_the_path() {
        let p = Path::new("/nonexistent-dir-momaro/x.png");
        let e = write_cost_layer_png(&[Cost::Finite(1.0)], 1, 1, None, p).unwrap_err();
        assert!(e.to_string().contains("/nonexistent-dir-momaro/x.png"), "{e}");
        let e = write_cost_layer_png(&[Cost::Finite(1.0)], 2, 1, None, p).unwrap_err();
        assert!(matches!(e, ImageError::BadLayer { len: 1, .. }));
    }

    #[test]
    fn all_layers_of_a_scene_are_written() {
        let ps = [
            Primitive::Ramp(Ramp {
                center: [1.0, 1.5],
                size: [1.0, 0.8],
                height: 0.2,
                yaw_deg: 0.0,
            }),
            Primitive::Pole(Pole { center: [2.0, 1.0], radius: 0.05, height: 0.15 }),
            Primitive::Pole(Pole { center: [2.0, 2.0], radius: 0.05, height: 0.5 }),
        ];
        let mut m = rasterise(&ps, [0.0, 0.0], [3.0, 3.0], 0.025).unwrap();
        for j in 100..120 {
            m.set(10, j, f64::NAN).unwrap();
        }
        let robot = RobotDescription::reference();
        let maps = CostMaps::build(&m, &robot, &Params::default()).unwrap();
        write_height_png(&m, &tmp("h.png")).unwrap();
        write_foot_cost_png(&maps, None, &tmp("f.png")).unwrap();
        write_body_cost_png(&maps, 0.0, 0.27, Some(2.0), &tmp("b.png")).unwrap();
        write_pose_cost_png(&maps, 0.0, 0.27, None, &tmp("p.png")).unwrap();
        let (w, h, buf) = read_png(&tmp("f.png"));
        assert_eq!((w, h), (120, 120));
        let has = |c: [u8; 3]| buf.chunks(3).any(|p| p == c);
        assert!(has(INFINITE_RGB) && has(UNKNOWN_RGB));
        let (_, _, hb) = read_png(&tmp("h.png"));
        assert!(
            hb.chunks(3).any(|p| p == UNKNOWN_RGB) && hb.chunks(3).any(|p| p == [255, 255, 255])
        );
    }
}
