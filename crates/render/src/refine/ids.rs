//! The polygon-ID view, one scanline at a time: which polygon of the display list owns
//! each pixel under the point sampling of the shading phases — the paper's polygon
//! identifier buffer, kept as one scanline instead of an image.
//!
//! The array draws it. Every polygon is sent point-sampled and flat, on two channels:
//! its identifier times [`SCALE`], and [`SCALE`] alone. A processor's first channel is
//! then the sum of the identifiers of the polygons that reached it and the second how
//! many did, so a pixel's owner is exactly what the shading phases' `Eval`s reach, and a
//! pixel reached twice (fragments that were not disjoint) is seen as [`SHARED`] rather
//! than read as another polygon's identifier. Both values are dyadic (`k · 2⁻²⁴`) and
//! every sum exact in `f64`.

use crate::error::RenderError;
use cwisim_isa::TraceHeader;
use cwisim_scene::{Polygon, ScreenScene, VertexIntensity};
use cwisim_xproc::{EngineWriter, LineOut, LineSink, Machine, Timing};
use cwisim_ypipe::{emit_rows, ScanPlan};

/// A pixel no polygon reaches.
pub const NONE: u32 = 0;
/// A pixel more than one polygon reaches.
pub const SHARED: u32 = u32::MAX;
/// The intensity step of one identifier: `2⁻²⁴`, so that identifiers up to
/// [`MAX_POLYGONS`] stay below 1 and exact.
pub const SCALE: f64 = 1.0 / (1u64 << 24) as f64;
/// The most polygons the view can name (identifiers `1..=MAX_POLYGONS`).
pub const MAX_POLYGONS: usize = (1 << 24) - 1;

/// The polygons of a scene, ready to be drawn as identifiers.
pub struct IdView {
    scene: ScreenScene,
}

impl IdView {
    /// The view of `screen`'s polygons: polygon `k` (in scene order) is identifier
    /// `k + 1`. More than [`MAX_POLYGONS`] polygons is an error.
    pub fn new(screen: &ScreenScene) -> Result<IdView, RenderError> {
        if screen.polygons.len() > MAX_POLYGONS {
            return Err(RenderError::Usage(format!(
                "the polygon-ID view names at most {MAX_POLYGONS} polygons; the scene has {}",
                screen.polygons.len()
            )));
        }
        let polygons = screen
            .polygons
            .iter()
            .enumerate()
            .map(|(k, p)| Polygon {
                vertices: p.vertices.clone(),
                intensity: vec![
                    VertexIntensity::from_slice(&[(k + 1) as f64 * SCALE, SCALE]);
                    p.vertices.len()
                ],
                depth: None,
            })
            .collect();
        Ok(IdView {
            scene: ScreenScene {
                width: screen.width,
                height: screen.height,
                channels: 2,
                polygons,
            },
        })
    }

    /// Pixel columns of a scanline.
    pub fn width(&self) -> usize {
        self.scene.width as usize
    }

    /// Calls `row(y, owners)` for every scanline, top to bottom; `owners[x]` is the
    /// identifier of the polygon owning pixel `x` ([`NONE`], or [`SHARED`]). Holds one
    /// scanline of owners at a time.
    pub fn scan(&self, row: &mut dyn FnMut(usize, &[u32])) -> Result<(), RenderError> {
        let options = super::frame::POINT;
        let plan = ScanPlan::new(&self.scene, &options);
        let header = TraceHeader::new(self.scene.width, self.scene.height, 2)
            .map_err(|e| RenderError::Usage(e.to_string()))?;
        let mut sink = Owners {
            owners: vec![NONE; self.width()],
            row,
        };
        let mut array =
            EngineWriter::<f64>::new(&header, &Machine::default(), Timing::Fast, &mut sink)?;
        emit_rows(&plan, &options, 0..self.scene.height, &mut array).map_err(RenderError::Array)?;
        cwisim_isa::TraceWrite::finish(&mut array).map_err(RenderError::Array)?;
        Ok(())
    }
}

/// The array's scanlines read back as owners.
struct Owners<'r> {
    owners: Vec<u32>,
    row: &'r mut dyn FnMut(usize, &[u32]),
}

impl LineSink<f64> for Owners<'_> {
    fn line(&mut self, line: LineOut<'_, f64>) {
        self.owners.fill(NONE);
        let (a, b) = line.span;
        for (x, v) in (a..b).zip(line.values.chunks_exact(2)) {
            self.owners[x] = owner(v[0], v[1]);
        }
        (self.row)(line.index as usize, &self.owners);
    }
}

/// The owner of a processor whose channels hold `sum` (of identifiers × [`SCALE`]) and
/// `count` (× [`SCALE`]).
fn owner(sum: f64, count: f64) -> u32 {
    let n = count / SCALE;
    if n == 0.0 {
        NONE
    } else if n == 1.0 {
        (sum / SCALE) as u32
    } else {
        SHARED
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(x0: f64, x1: f64, y0: f64, y1: f64) -> Polygon {
        Polygon::new(
            vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]],
            vec![vec![0.5]; 4],
        )
    }

    fn view(polygons: Vec<Polygon>) -> Vec<Vec<u32>> {
        let screen = ScreenScene {
            width: 8,
            height: 4,
            channels: 1,
            polygons,
        };
        let mut rows = vec![Vec::new(); 4];
        IdView::new(&screen)
            .unwrap()
            .scan(&mut |y, owners| rows[y] = owners.to_vec())
            .unwrap();
        rows
    }

    #[test]
    fn two_squares_side_by_side_own_their_pixels() {
        let rows = view(vec![square(0.0, 4.0, 0.0, 4.0), square(4.0, 8.0, 1.0, 3.0)]);
        assert_eq!(rows[0], [1, 1, 1, 1, 0, 0, 0, 0]);
        assert_eq!(rows[1], [1, 1, 1, 1, 2, 2, 2, 2]);
        assert_eq!(rows[2], [1, 1, 1, 1, 2, 2, 2, 2]);
        assert_eq!(rows[3], [1, 1, 1, 1, 0, 0, 0, 0]);
    }

    #[test]
    fn overlapping_polygons_are_seen_as_shared() {
        let rows = view(vec![square(0.0, 4.0, 0.0, 4.0), square(2.0, 6.0, 0.0, 4.0)]);
        assert_eq!(rows[2], [1, 1, SHARED, SHARED, 2, 2, 0, 0]);
    }
}
