//! Bands of rows emitted independently concatenate to exactly the whole emission: the
//! basis of rendering bands in parallel with output identical to the serial run.

use cwisim_isa::text::TextWriter;
use cwisim_isa::TraceWrite;
use cwisim_scene::{Polygon, ScreenScene};
use cwisim_ypipe::{
    emit, emit_rows, header, Antialias, Claim, EmitStats, Options, ScanPlan, Shading,
};
use proptest::prelude::*;

fn text_of(
    scene: &ScreenScene,
    f: impl FnOnce(&mut dyn TraceWrite) -> EmitStats,
) -> (String, EmitStats) {
    let mut buf = Vec::new();
    let stats;
    {
        let mut w = TextWriter::new(&mut buf, &header(scene)).expect("header");
        stats = f(&mut w);
        w.finish().expect("finish");
    }
    (String::from_utf8(buf).expect("utf-8"), stats)
}

fn polygon() -> impl Strategy<Value = Polygon> {
    (
        prop::collection::vec((-4.0f64..36.0, -4.0f64..28.0), 3..=3),
        0.0f64..1.0,
        0.0f64..1.0,
    )
        .prop_map(|(v, a, b)| {
            Polygon::new(
                v.iter().map(|&(x, y)| [x, y]).collect(),
                vec![vec![a], vec![b], vec![0.5]],
            )
        })
        .prop_filter("non-degenerate", |p| {
            cwisim_ypipe::exact::polygon_area(p) > 1e-3
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn bands_concatenate_to_the_whole_stream(
        polygons in prop::collection::vec(polygon(), 1..6),
        cuts in prop::collection::vec(0u32..=24, 0..5),
        flat in any::<bool>(),
        boxed in any::<bool>(),
        claim in any::<bool>(),
    ) {
        let scene = ScreenScene { width: 32, height: 24, channels: 1, polygons };
        let options = Options {
            shading: if flat { Shading::Flat } else { Shading::Gouraud },
            aa: if boxed { Antialias::Box } else { Antialias::None },
            claim: if claim { Claim::Eval0 { tolerance: 1.0 / 512.0 } } else { Claim::Accumulate },
        };
        let (whole, whole_stats) = text_of(&scene, |w| emit(&scene, &options, w).expect("emit"));
        let mut cuts = cuts;
        cuts.push(0);
        cuts.push(24);
        cuts.sort_unstable();
        cuts.dedup();
        // the frame's trapezia made at once, then band by band: the same stream
        for plan in [ScanPlan::new(&scene, &options), ScanPlan::by_bands(&scene, &options)] {
            let (banded, banded_stats) = text_of(&scene, |w| {
                let mut stats = plan.scene_stats();
                for band in cuts.windows(2) {
                    stats.add_band(&emit_rows(&plan, &options, band[0]..band[1], w).expect("emit"));
                }
                stats
            });
            prop_assert_eq!(&whole, &banded);
            prop_assert_eq!(&whole_stats, &banded_stats);
        }
    }
}

/// Keeps the instructions and asks for comments: `emit` then composes each row's note
/// and buffers the row, where a sink without comments is written to directly.
struct Commented(Vec<cwisim_isa::Instruction>);

impl TraceWrite for Commented {
    fn write(&mut self, i: &cwisim_isa::Instruction) -> std::io::Result<()> {
        self.0.push(i.clone());
        Ok(())
    }
    fn comment(&mut self, _text: &str) -> std::io::Result<()> {
        Ok(())
    }
    fn wants_comments(&self) -> bool {
        true
    }
    fn finish(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn rows_written_directly_equal_rows_buffered_with_their_notes(
        polygons in prop::collection::vec(polygon(), 1..6),
        flat in any::<bool>(),
        aa in 0usize..3,
        claim in any::<bool>(),
    ) {
        let scene = ScreenScene { width: 32, height: 24, channels: 1, polygons };
        let options = Options {
            shading: if flat { Shading::Flat } else { Shading::Gouraud },
            aa: [Antialias::Box, Antialias::BoxCentre, Antialias::None][aa],
            claim: if claim { Claim::Eval0 { tolerance: 1.0 / 512.0 } } else { Claim::Accumulate },
        };
        let mut direct: Vec<cwisim_isa::Instruction> = Vec::new();
        let direct_stats = emit(&scene, &options, &mut direct).expect("emit");
        let mut buffered = Commented(Vec::new());
        let buffered_stats = emit(&scene, &options, &mut buffered).expect("emit");
        prop_assert_eq!(direct, buffered.0);
        prop_assert_eq!(direct_stats, buffered_stats);
    }
}
