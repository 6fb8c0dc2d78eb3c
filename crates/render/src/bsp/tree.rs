//! A BSP tree (Fuchs, Kedem & Naylor) over a world scene's triangles, built in world
//! space, and its traversal from an eye: back to front (far subtree, node, near
//! subtree) or front to back (the reverse).
//!
//! A polygon that spans a node's plane is **split** in two convex pieces; every piece
//! keeps, at each vertex, its world point, its screen point and `1/depth`, and its
//! intensity. A new vertex on the world edge `a → b` at `t` (where the plane cuts it) lies
//! on the screen edge at `s = t·z_b / ((1 − t)·z_a + t·z_b)` (`z = 1/w` the depth:
//! perspective maps the world edge onto the screen edge, not linearly), and its intensity
//! and `1/depth` are the screen-affine values there, so the pieces cover exactly what
//! the triangle covers and shade it as it is shaded.

use cwisim_scene::Vector;
use glam::DVec3;

/// A convex polygon of the tree: per vertex its world point, screen point, `1/depth` and
/// intensity; and the scene polygon it is a piece of.
#[derive(Clone, Debug, PartialEq)]
pub struct Piece {
    /// World points.
    pub world: Vec<DVec3>,
    /// Screen points.
    pub screen: Vec<[f64; 2]>,
    /// `1/depth` at each vertex.
    pub w: Vec<f64>,
    /// Intensity at each vertex.
    pub intensity: Vec<Vector>,
    /// The scene polygon (index into the list the tree was built from).
    pub source: u32,
}

/// Where the tree is seen from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum View {
    /// A perspective camera's eye.
    Eye(DVec3),
    /// A parallel view looking along a direction (screen scenes: `(x, y, depth)` seen
    /// along `+depth`).
    Along(DVec3),
}

/// How many pieces of a list, spread evenly over it, are tried as its node's splitter.
pub const CANDIDATES: usize = 8;
/// What a split costs in the choice of a splitter, against one piece of imbalance between
/// the two sides: splits add pieces, imbalance adds depth (and a tree as deep as its
/// pieces takes quadratic time to build).
pub const SPLIT_WEIGHT: u64 = 4;

/// A plane `n·p + d = 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Plane {
    n: DVec3,
    d: f64,
}

impl Plane {
    /// The plane of a piece, its normal by Newell's method (any planar polygon, whatever
    /// its first vertices); `None` when it has no area.
    fn of(p: &Piece) -> Option<Plane> {
        let m = p.world.len();
        let mut n = DVec3::ZERO;
        let mut centre = DVec3::ZERO;
        for i in 0..m {
            let (a, b) = (p.world[i], p.world[(i + 1) % m]);
            n.x += (a.y - b.y) * (a.z + b.z);
            n.y += (a.z - b.z) * (a.x + b.x);
            n.z += (a.x - b.x) * (a.y + b.y);
            centre += a;
        }
        let len = n.length();
        if !(len > 0.0 && len.is_finite()) {
            return None;
        }
        let n = n / len;
        Some(Plane {
            n,
            d: -n.dot(centre / m as f64),
        })
    }

    fn distance(&self, p: DVec3) -> f64 {
        self.n.dot(p) + self.d
    }
}

struct Node {
    plane: Plane,
    /// Pieces in the node's plane.
    on: Vec<u32>,
    front: Option<usize>,
    back: Option<usize>,
}

/// The tree: its pieces and nodes.
pub struct Tree {
    /// Every piece (the scene's polygons, split where they span a plane).
    pub pieces: Vec<Piece>,
    nodes: Vec<Node>,
    root: Option<usize>,
    /// Polygons split (each split adds one piece).
    pub splits: u64,
    /// The deepest node (root: 1).
    pub depth: u64,
}

/// Which side of a plane a piece lies on.
enum Side {
    On,
    Front,
    Back,
    Both,
}

fn classify(plane: &Plane, p: &Piece, eps: f64) -> Side {
    let (mut front, mut back) = (false, false);
    for &v in &p.world {
        let d = plane.distance(v);
        front |= d > eps;
        back |= d < -eps;
    }
    match (front, back) {
        (false, false) => Side::On,
        (true, false) => Side::Front,
        (false, true) => Side::Back,
        (true, true) => Side::Both,
    }
}

/// `p` cut by `plane`: (front piece, back piece).
fn split(plane: &Plane, p: &Piece, eps: f64, channels: usize) -> (Piece, Piece) {
    let empty = || Piece {
        world: Vec::new(),
        screen: Vec::new(),
        w: Vec::new(),
        intensity: Vec::new(),
        source: p.source,
    };
    let (mut f, mut b) = (empty(), empty());
    let push = |q: &mut Piece, k: usize| {
        q.world.push(p.world[k]);
        q.screen.push(p.screen[k]);
        q.w.push(p.w[k]);
        q.intensity.push(p.intensity[k]);
    };
    let n = p.world.len();
    for i in 0..n {
        let j = (i + 1) % n;
        let (di, dj) = (plane.distance(p.world[i]), plane.distance(p.world[j]));
        if di > eps {
            push(&mut f, i);
        } else if di < -eps {
            push(&mut b, i);
        } else {
            push(&mut f, i);
            push(&mut b, i);
        }
        if (di > eps && dj < -eps) || (di < -eps && dj > eps) {
            let t = di / (di - dj);
            let (za, zb) = (1.0 / p.w[i], 1.0 / p.w[j]);
            let s = t * zb / ((1.0 - t) * za + t * zb);
            let (sa, sb) = (p.screen[i], p.screen[j]);
            let screen = [sa[0] + s * (sb[0] - sa[0]), sa[1] + s * (sb[1] - sa[1])];
            let world = p.world[i] + t * (p.world[j] - p.world[i]);
            let w = p.w[i] + s * (p.w[j] - p.w[i]);
            let (ia, ib) = (&p.intensity[i], &p.intensity[j]);
            let intensity = cwisim_scene::vector(channels, |c| ia[c] + s * (ib[c] - ia[c]));
            for q in [&mut f, &mut b] {
                q.world.push(world);
                q.screen.push(screen);
                q.w.push(w);
                q.intensity.push(intensity);
            }
        }
    }
    (f, b)
}

impl Tree {
    /// The tree of `pieces` (triangles or convex polygons with at least three world
    /// points; pieces without a plane are kept in the node of the first plane they meet
    /// as coplanar). Each node's splitter is, of [`CANDIDATES`] pieces spread evenly over
    /// its list, the one of least cost: [`SPLIT_WEIGHT`] per piece it splits plus the
    /// difference between its two sides (ties: the first) — the balance keeps the tree's
    /// depth near `log n`, so that it builds in `O(n log n)`, not `O(n²)`. `eps`: the
    /// distance within which a vertex counts as on a plane.
    ///
    /// The build stops once its splits make more than `max_pieces` pieces: `Err` with
    /// the pieces made then (`max_pieces + 1`), so that a caller can refuse a tree past
    /// its memory budget before it grows further.
    pub fn build(
        pieces: Vec<Piece>,
        eps: f64,
        channels: usize,
        max_pieces: usize,
    ) -> Result<Tree, usize> {
        let mut tree = Tree {
            pieces,
            nodes: Vec::new(),
            root: None,
            splits: 0,
            depth: 0,
        };
        // work: (pieces of a subtree, where its node index goes, its depth)
        enum Slot {
            Root,
            Front(usize),
            Back(usize),
        }
        let all: Vec<u32> = (0..tree.pieces.len() as u32).collect();
        let mut work = vec![(all, Slot::Root, 1u64)];
        while let Some((list, slot, depth)) = work.pop() {
            // the splitter: of CANDIDATES pieces with a plane, spread evenly over the
            // list (neighbours in a mesh share nearly one plane, and one of them splits
            // the rest no better than another), the one of the least cost: a split costs
            // SPLIT_WEIGHT, an unbalanced piece 1 (then the first)
            let stride = (list.len() / CANDIDATES).max(1);
            let candidates: Vec<(usize, Plane)> = (0..list.len())
                .step_by(stride)
                .filter_map(|i| Plane::of(&tree.pieces[list[i] as usize]).map(|p| (i, p)))
                .take(CANDIDATES)
                .chain(
                    // a list whose evenly spread pieces have no plane: the first that has
                    list.iter()
                        .enumerate()
                        .find_map(|(i, &k)| Plane::of(&tree.pieces[k as usize]).map(|p| (i, p))),
                )
                .collect();
            let best = candidates.iter().min_by_key(|(_, plane)| {
                let (mut splits, mut front, mut back) = (0u64, 0i64, 0i64);
                for &k in &list {
                    match classify(plane, &tree.pieces[k as usize], eps) {
                        Side::On => {}
                        Side::Front => front += 1,
                        Side::Back => back += 1,
                        Side::Both => splits += 1,
                    }
                }
                splits * SPLIT_WEIGHT + (front - back).unsigned_abs()
            });
            let Some(&(at, plane)) = best else {
                // no plane among them: they cover nothing; keep them in a leaf
                let node = tree.nodes.len();
                tree.nodes.push(Node {
                    plane: Plane {
                        n: DVec3::Z,
                        d: 0.0,
                    },
                    on: list,
                    front: None,
                    back: None,
                });
                tree.attach(slot_index(&slot), node);
                tree.depth = tree.depth.max(depth);
                continue;
            };
            let (mut on, mut front, mut back) = (Vec::new(), Vec::new(), Vec::new());
            on.push(list[at]);
            for (i, &k) in list.iter().enumerate() {
                if i == at {
                    continue;
                }
                match classify(&plane, &tree.pieces[k as usize], eps) {
                    Side::On => on.push(k),
                    Side::Front => front.push(k),
                    Side::Back => back.push(k),
                    Side::Both => {
                        let (f, b) = split(&plane, &tree.pieces[k as usize], eps, channels);
                        tree.splits += 1;
                        tree.pieces[k as usize] = f;
                        front.push(k);
                        back.push(tree.pieces.len() as u32);
                        tree.pieces.push(b);
                        if tree.pieces.len() > max_pieces {
                            return Err(tree.pieces.len());
                        }
                    }
                }
            }
            let node = tree.nodes.len();
            tree.nodes.push(Node {
                plane,
                on,
                front: None,
                back: None,
            });
            tree.attach(slot_index(&slot), node);
            tree.depth = tree.depth.max(depth);
            if !back.is_empty() {
                work.push((back, Slot::Back(node), depth + 1));
            }
            if !front.is_empty() {
                work.push((front, Slot::Front(node), depth + 1));
            }
        }
        fn slot_index(s: &Slot) -> (Option<usize>, bool) {
            match s {
                Slot::Root => (None, false),
                Slot::Front(n) => (Some(*n), true),
                Slot::Back(n) => (Some(*n), false),
            }
        }
        Ok(tree)
    }

    fn attach(&mut self, slot: (Option<usize>, bool), node: usize) {
        match slot {
            (None, _) => self.root = Some(node),
            (Some(parent), true) => self.nodes[parent].front = Some(node),
            (Some(parent), false) => self.nodes[parent].back = Some(node),
        }
    }

    /// The pieces in display order from `view`: back to front (`front_to_back` false) or
    /// front to back.
    pub fn order(&self, view: View, front_to_back: bool) -> Vec<u32> {
        let mut out = Vec::with_capacity(self.pieces.len());
        // explicit stack: Visit(node) expands; Emit(node) outputs the node's pieces
        enum Step {
            Visit(usize),
            Emit(usize),
        }
        let mut stack: Vec<Step> = self.root.map(Step::Visit).into_iter().collect();
        while let Some(step) = stack.pop() {
            match step {
                Step::Emit(n) => out.extend_from_slice(&self.nodes[n].on),
                Step::Visit(n) => {
                    let node = &self.nodes[n];
                    let eye_front = match view {
                        View::Eye(eye) => node.plane.distance(eye) >= 0.0,
                        // the viewer at −∞ along the direction
                        View::Along(dir) => node.plane.n.dot(dir) <= 0.0,
                    };
                    let (near, far) = if eye_front {
                        (node.front, node.back)
                    } else {
                        (node.back, node.front)
                    };
                    // pushed in reverse of the order they run
                    let (first, last) = if front_to_back {
                        (near, far)
                    } else {
                        (far, near)
                    };
                    if let Some(l) = last {
                        stack.push(Step::Visit(l));
                    }
                    stack.push(Step::Emit(n));
                    if let Some(f) = first {
                        stack.push(Step::Visit(f));
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(z: f64, source: u32) -> Piece {
        let world = vec![
            DVec3::new(-1.0, -1.0, z),
            DVec3::new(1.0, -1.0, z),
            DVec3::new(0.0, 1.0, z),
        ];
        Piece {
            screen: world.iter().map(|p| [p.x, p.y]).collect(),
            w: vec![1.0 / z; 3],
            intensity: vec![Vector::default(); 3],
            world,
            source,
        }
    }

    #[test]
    fn parallel_planes_order_by_the_eye() {
        let t = Tree::build(
            vec![tri(5.0, 0), tri(3.0, 1), tri(4.0, 2)],
            1e-9,
            1,
            usize::MAX,
        )
        .unwrap();
        assert_eq!(t.splits, 0);
        let eye = DVec3::ZERO;
        assert_eq!(t.order(View::Eye(eye), true), vec![1, 2, 0]);
        assert_eq!(t.order(View::Eye(eye), false), vec![0, 2, 1]);
        let behind = DVec3::new(0.0, 0.0, 10.0);
        assert_eq!(t.order(View::Eye(behind), true), vec![0, 2, 1]);
        assert_eq!(t.order(View::Along(DVec3::Z), true), vec![1, 2, 0]);
    }

    #[test]
    fn a_spanning_triangle_is_split_into_pieces_on_both_sides() {
        // a vertical triangle through the plane z = 4 of the first
        let world = vec![
            DVec3::new(0.0, -1.0, 2.0),
            DVec3::new(0.0, 1.0, 2.0),
            DVec3::new(0.0, 0.0, 6.0),
        ];
        let spanning = Piece {
            screen: world.iter().map(|p| [p.y / p.z, p.z]).collect(),
            w: world.iter().map(|p| 1.0 / p.z).collect(),
            intensity: vec![Vector::default(); 3],
            world,
            source: 1,
        };
        // a bound of two pieces stops the split that makes the third
        assert_eq!(
            Tree::build(vec![tri(4.0, 0), spanning.clone()], 1e-9, 1, 2).err(),
            Some(3)
        );
        assert!(Tree::build(vec![tri(4.0, 0), spanning.clone()], 1e-9, 1, 3).is_ok());
        let t = Tree::build(vec![tri(4.0, 0), spanning], 1e-9, 1, usize::MAX).unwrap();
        assert_eq!(t.splits, 1);
        assert_eq!(t.pieces.len(), 3);
        let order = t.order(View::Eye(DVec3::ZERO), true);
        // the near piece (z < 4), the splitter, the far piece
        assert_eq!(order.len(), 3);
        assert_eq!(order[1], 0);
        let near = &t.pieces[order[0] as usize];
        assert!(near.world.iter().all(|p| p.z <= 4.0 + 1e-12));
        // the new vertices lie on the plane, and on the screen where the camera puts them
        for (p, w) in near.world.iter().zip(&near.w) {
            assert!((1.0 / w - p.z).abs() < 1e-12);
        }
    }
}
