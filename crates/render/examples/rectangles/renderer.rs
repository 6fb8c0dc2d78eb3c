//! A renderer of flat-shaded, axis-aligned rectangles: the smallest complete
//! [`Renderer`] a library user can write, and the worked example of
//! `docs/RENDERERS.md`.
//!
//! Each rectangle covers whole pixels `[x0, x1) × [y0, y1)` with one value. Rectangles
//! add up (the array accumulates), so one `Eval1` per rectangle per row is the whole
//! stream: no sorting, no visibility. Every row ends with its `Refresh`, empty or not.

use cwisim_isa::{Instruction, Intensity, TraceHeader, TraceWrite};
use cwisim_render::{Counters, FramePlan, RenderError, Renderer};
use cwisim_xproc::Image;
use std::io;
use std::ops::Range;

/// Whole pixels `[x0, x1) × [y0, y1)`, one grey value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Left column (inclusive).
    pub x0: u32,
    /// Top row (inclusive).
    pub y0: u32,
    /// Right column (exclusive).
    pub x1: u32,
    /// Bottom row (exclusive).
    pub y1: u32,
    /// Its value.
    pub value: f64,
}

/// Rectangles in an image of `width × height` grey pixels.
pub struct Rectangles {
    width: u32,
    height: u32,
    rects: Vec<Rect>,
}

impl Rectangles {
    /// The renderer of `rects`, clipped to `width × height`; an empty or non-finite one
    /// is refused with its index.
    pub fn new(width: u32, height: u32, rects: Vec<Rect>) -> Result<Rectangles, RenderError> {
        TraceHeader::new(width, height, 1).map_err(|e| RenderError::Usage(e.to_string()))?;
        for (k, r) in rects.iter().enumerate() {
            if r.x0 >= r.x1 || r.y0 >= r.y1 || !r.value.is_finite() {
                return Err(RenderError::Usage(format!(
                    "rectangle {k} is empty or its value is not finite: {r:?}"
                )));
            }
        }
        Ok(Rectangles {
            width,
            height,
            rects,
        })
    }
}

/// The example's scene: three overlapping rectangles in 16 × 10 pixels.
pub fn three_rectangles() -> Rectangles {
    let rect = |x0, y0, x1, y1, value| Rect {
        x0,
        y0,
        x1,
        y1,
        value,
    };
    Rectangles::new(
        16,
        10,
        vec![
            rect(2, 1, 12, 6, 0.5),
            rect(6, 3, 15, 9, 0.25),
            rect(0, 7, 4, 10, 1.0),
        ],
    )
    .expect("valid rectangles")
}

/// A frame needs no preparation: the plan is the renderer itself.
struct Plan<'a>(&'a Rectangles);

impl FramePlan for Plan<'_> {
    fn counters(&self) -> Counters {
        Counters::default().with("rectangles", self.0.rects.len() as u64)
    }

    fn emit_rows(&self, rows: Range<u32>, sink: &mut dyn TraceWrite) -> io::Result<Counters> {
        let mut spans = 0;
        for y in rows {
            for r in &self.0.rects {
                let x1 = r.x1.min(self.0.width);
                if (r.y0..r.y1).contains(&y) && r.x0 < x1 {
                    sink.write(&Instruction::eval1(
                        r.x0,
                        x1 - r.x0,
                        Intensity::grey(r.value),
                    ))?;
                    spans += 1;
                }
            }
            sink.write(&Instruction::refresh())?;
        }
        Ok(Counters::default().with("spans", spans))
    }
}

impl Renderer for Rectangles {
    fn name(&self) -> &'static str {
        "rectangles"
    }

    fn header(&self) -> TraceHeader {
        TraceHeader::new(self.width, self.height, 1).expect("checked by new")
    }

    fn frame<'a>(
        &'a self,
        _index: u32,
        _previous: Option<&'a Image>,
    ) -> Result<Box<dyn FramePlan + 'a>, RenderError> {
        Ok(Box::new(Plan(self)))
    }

    fn settings_phrase(&self) -> String {
        "flat rectangles, whole pixels".into()
    }
}
