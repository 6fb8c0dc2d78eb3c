//! The scenes built into `cwisim` (`cwisim scenes` lists them). Their files are in
//! `crates/world/scenes/`: copy one to start a scene of your own.

/// A scene built into the binary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Embedded {
    /// The name to give `cwisim render`.
    pub name: &'static str,
    /// One line about it.
    pub about: &'static str,
    /// The scene file.
    pub text: &'static str,
}

/// Every embedded scene; the first is the default of `cwisim render`.
pub const EMBEDDED: &[Embedded] = &[
    Embedded {
        name: "pot",
        about: "world, grey: a lit pot, a surface of revolution of trapezia and triangles (the report's figures 24 and 28), open at the top so its inside shows behind the rim",
        text: include_str!("../scenes/pot.json"),
    },
    Embedded {
        name: "fig25",
        about: "screen, grey: the three triangles P, Q, R of the report's figure 25 (the Identifier example)",
        text: include_str!("../scenes/fig25.json"),
    },
    Embedded {
        name: "cases12",
        about: "screen, grey: one trapezium row per DO_FILL case 1–12, four to a row (at its own size; --size rescales and so changes the cases)",
        text: include_str!("../scenes/cases12.json"),
    },
    Embedded {
        name: "still-life",
        about: "world, RGB: a red vase, a green box and a blue cone on a table, occluding each other",
        text: include_str!("../scenes/still-life.json"),
    },
    Embedded {
        name: "glass",
        about: "world, RGB, 320×240: a red vase behind a glass box (transmittance 0.6) and a blue cone behind a pane (0.5) that overlaps the box; woo-chall and sbuffer --sbuffer transparent composite the layers, the others draw the nearest surface",
        text: include_str!("../scenes/glass.json"),
    },
    Embedded {
        name: "bowl",
        about: "world, RGB: a red ball above a shallow bowl and a blue cone in it; the one light casts shadows, the ball's onto the bowl's curved inside",
        text: include_str!("../scenes/bowl.json"),
    },
    Embedded {
        name: "teapot",
        about: "world, grey, 500×500 as in Nishita et al.: the Utah teapot, Newell's 32 bicubic Bézier patches with Crow's bottom, tessellated 8×8 per patch, two-sided (its inside shows through the lid gap)",
        text: include_str!("../scenes/teapot.json"),
    },
    Embedded {
        name: "teapot-floor",
        about: "world, grey, 500×500: the teapot standing on a floor, its light casting the teapot's shadow (Nishita et al.'s §7 scene: nishita draws the shadows on its patches, the other renderers on the tessellation)",
        text: include_str!("../scenes/teapot-floor.json"),
    },
    Embedded {
        name: "teapot-textured",
        about: "world, grey, 500×500: the teapot with a 4×4 checkerboard on each patch, in the patch's own (u, v) (Nishita et al.'s figure 10b)",
        text: include_str!("../scenes/teapot-textured.json"),
    },
    Embedded {
        name: "textures4",
        about: "world, RGB, 400×300: four textured objects (two pictures, a striped vase, a rug) placed so that at most three share a scanline — Woo & Chall's figure 10 case: four textures, memory for three (woo-chall loads and frees them in scanline order)",
        text: include_str!("../scenes/textures4.json"),
    },
];

/// The embedded scene called `name`.
pub fn embedded(name: &str) -> Option<&'static Embedded> {
    EMBEDDED.iter().find(|e| e.name == name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_embedded_scene_reads_and_projects() {
        for e in EMBEDDED {
            let scene =
                crate::parse_any(e.text, None).unwrap_or_else(|err| panic!("{}: {err}", e.name));
            if let crate::AnyScene::World(w) = scene {
                let (tris, _) =
                    crate::project::project(&w, cwisim_scene::Shading::Gouraud).unwrap();
                assert!(!tris.is_empty(), "{}", e.name);
            }
        }
    }
}
