//! A binned-SAH bounding volume hierarchy over triangles with two-sided closest-hit and any-hit
//! (shadow ray) queries, in the world frame of `docs/CONVENTIONS.md` (any consistent length unit).
//!
//! **Build** (Wald 2007, "On fast construction of SAH-based bounding volume hierarchies"): a
//! node of at most 4 triangles is a leaf; a larger one bins its triangles' centroids into 16
//! equal bins per axis over the centroid bounds and splits at the plane of least
//! surface-area-heuristic cost `n_L A(L) + n_R A(R)` (`A` the surface area of a child's box, `n`
//! its triangle count). Letting the SAH also split nodes of 2 to 4 triangles was measured: more,
//! smaller leaves and slower queries. When no plane separates the centroids (they coincide), or
//! from depth 32 on, the node is split at the median centroid along its widest centroid axis
//! (ties by triangle index), which halves it: every root-to-leaf path therefore has at most 63
//! nodes whatever the input (10000 identical triangles give a balanced tree), and the fixed
//! 93-entry traversal stack of the four-wide walk cannot overflow ("Traversal"). Subtrees of
//! 2048 triangles or more are built in parallel (rayon); each subtree is a pure function of its
//! triangles, so the result is identical for any thread count. Cost: O(n log n) for well-spread
//! input (O(n) per level, O(log n) levels), at most O(64 n) whatever the input; memory 128
//! bytes per four-wide node (about one per two binary inner nodes) plus 40 bytes per triangle.
//!
//! **Layout** (a four-wide tree collapsed from the binary one, as in Wald et al. 2008, "Getting
//! rid of packets", and Embree's BVH4): each node of the binary tree is replaced by its
//! grandchildren where its children are inner nodes (its leaf children stay), and a node left
//! with three children opens its widest inner one too, so every four-wide inner node lies at
//! least two binary levels below its parent and a path has at most 31 of them. The (up to)
//! four children of a node sit side by side in one 128-byte, cache-line aligned record with
//! their boxes stored corner by corner and axis by axis (lane `i` is child `i`), so one SIMD
//! slab test checks all four; an unused slot holds the empty box, which no ray enters. The
//! leaves are the binary tree's, so queries answer exactly as before, and the walk visits
//! about half as many nodes: on the bunny scenes' reference renders 4.6 to 4.9 % fewer
//! instructions a path than the binary layout (cachegrind; BENCHMARKS.md, "A four-wide BVH").
//! Triangles are stored in leaf order as their three corners (not edges: shared corners must
//! stay bit-identical for the watertight test), with the input index beside them.
//!
//! **Ray-box** (Williams et al. 2005; Ize 2013, "Robust BVH ray traversal"): slabs with the
//! precomputed inverse direction clamped to `+-f32::MAX`, so a zero direction component never
//! produces `0 * inf = NaN`; per axis the near and far plane picked by the sign of the inverse
//! direction (Williams' ordering: the same values as `min`/`max` of the two plane distances).
//! Far distances and the best hit distance are widened by `2^-16` of their magnitude in every
//! culling comparison: more than the rounding of the slab distances (Ize's `1 + 2 gamma_3`, flat
//! boxes of axis-aligned triangles included) and of a triangle's `t`, so a box never culls a hit
//! that the triangle test alone would report.
//!
//! **Ray-triangle** (Woop, Benthin & Wald 2013, "Watertight ray/triangle intersection", JCGT
//! 2(1)): the corners are translated to the ray origin and sheared so that the ray becomes the
//! +z axis of its dominant direction component; the three 2D edge functions `U, V, W` (weights of
//! corners 0, 1, 2) are recomputed in f64 when one is exactly zero, and a triangle is hit when
//! they share a sign (either sign: both faces), `t = (U A_z + V B_z + W C_z) / (U + V + W)`.
//! Neighbours compute their shared edge function from the same floats, so a ray through a shared
//! edge or corner always hits at least one of them. The dominant axis is a const generic: one
//! branch per ray, none per triangle. A hit is reported only when `t` exceeds its own
//! conservative rounding-error bound `delta_t` (Pharr, Jakob and Humphreys, *Physically Based
//! Rendering*, 4th ed., section 6.8.4): a ray leaving a surface from an origin offset by that
//! surface's hit-point error bound can then never hit the surface again, however large the
//! triangle, and `t_min = 0` is the right lower limit for such rays.
//!
//! **Traversal**: for closest hits the nearest child entered first, the others pushed farthest
//! first with their entry distances on an explicit 93-entry stack (no allocation per query;
//! three pushes per node on a path of at most 31); popped subtrees farther than the best hit
//! are skipped. Shadow rays take the children in slot order: any blocker ends the walk.
//! Closest-hit ties (equal `t`) go to the smallest input index, so the answer is that of a
//! brute-force loop over all triangles, whatever the tree or the order of traversal. Expected
//! cost O(log n) per ray.

use glam::{Vec3, Vec3A, Vec4};

use crate::ray::{Hit, Ray, gamma};

/// Centroid bins per axis in the SAH sweep.
const BINS: usize = 16;
/// Nodes with at most this many triangles are leaves, larger ones are split.
const MAX_LEAF: usize = 4;
/// Nodes at this depth (root 0) or deeper are split at the median only: the count halves at each
/// of them, so fewer than 2^32 triangles end in leaves by depth 62.
const SAH_MAX_DEPTH: usize = 32;
/// Nodes on the longest root-to-leaf path of the binary tree, at most (module notes).
const MAX_DEPTH: usize = 63;
/// Traversal stack entries: each four-wide inner node on a path pushes at most three children,
/// and a path has at most half the binary tree's inner nodes (`MAX_DEPTH - 1`), rounded up.
const STACK_SIZE: usize = 3 * (MAX_DEPTH - 1).div_ceil(2);
/// Subtrees with at least this many triangles are built in parallel.
const PARALLEL_MIN: usize = 2048;
/// Relative widening of box far distances and of the best distance in culling comparisons.
const WIDEN: f32 = 1.0 / 65536.0;

/// A bounding volume hierarchy over a triangle soup; see the module notes.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// Inner nodes of the four-wide tree in depth-first order, each holding its (up to) four
    /// children's boxes and references.
    nodes: Vec<QuadNode>,
    /// The root: a node index (`count == 0`) or a leaf.
    root: NodeRef,
    /// Bounds of all triangles.
    bounds: Option<(Vec3, Vec3)>,
    /// Corners `(v0, v1, v2)` of each triangle, in leaf order.
    triangles: Vec<[f32; 9]>,
    /// Input index of each triangle, in leaf order.
    indices: Vec<u32>,
    /// Nodes on the longest root-to-leaf path of the binary tree as built.
    depth: usize,
    /// Inner nodes of the binary tree as built.
    binary_inner: usize,
}

/// A node reference: `count == 0` means an inner node `nodes[child]`, otherwise a leaf of
/// `count` triangles starting at `child` in leaf order.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct NodeRef {
    child: u32,
    count: u32,
}

/// Up to four sibling nodes: `bounds[0]` their lower corners and `bounds[1]` their upper ones,
/// each stored axis by axis (lane `i` of `bounds[s][axis]` is child `i`'s), so one SIMD slab
/// test checks all four; two cache lines. An unused slot has the empty box (`lo = +inf`,
/// `hi = -inf`), which the slab test never enters.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(64))]
struct QuadNode {
    bounds: [[Vec4; 3]; 2],
    child: [u32; 4],
    count: [u32; 4],
}

impl QuadNode {
    /// The node over `children` (one to four boxes with their references).
    fn new(children: &[(Aabb, NodeRef)]) -> Self {
        let mut node = QuadNode {
            bounds: [[Vec4::INFINITY; 3], [Vec4::NEG_INFINITY; 3]],
            child: [0; 4],
            count: [0; 4],
        };
        for (i, (aabb, r)) in children.iter().enumerate() {
            for axis in 0..3 {
                node.bounds[0][axis][i] = aabb.lo[axis];
                node.bounds[1][axis][i] = aabb.hi[axis];
            }
            node.child[i] = r.child;
            node.count[i] = r.count;
        }
        node
    }

    fn get(&self, i: usize) -> NodeRef {
        NodeRef {
            child: self.child[i],
            count: self.count[i],
        }
    }
}

/// Axis-aligned box; the empty box has `lo = +inf`, `hi = -inf`.
#[derive(Clone, Copy, Debug)]
struct Aabb {
    lo: Vec3A,
    hi: Vec3A,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        lo: Vec3A::INFINITY,
        hi: Vec3A::NEG_INFINITY,
    };

    fn union(self, o: Aabb) -> Aabb {
        Aabb {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }

    fn grow(self, p: Vec3A) -> Aabb {
        Aabb {
            lo: self.lo.min(p),
            hi: self.hi.max(p),
        }
    }

    /// Half the surface area (zero for an empty or flat-in-two-axes box).
    fn half_area(self) -> f32 {
        let d = (self.hi - self.lo).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

/// A triangle during the build: its bounds and input index.
#[derive(Clone, Copy, Debug)]
struct Prim {
    bounds: Aabb,
    index: u32,
}

impl Prim {
    /// Twice the centroid of the bounds (the factor does not change any split).
    fn centroid2(&self) -> Vec3A {
        self.bounds.lo + self.bounds.hi
    }
}

/// The tree as the recursive build makes it, before flattening.
enum BuildNode {
    Leaf {
        bounds: Aabb,
        first: u32,
        count: u32,
    },
    Inner {
        bounds: Aabb,
        children: Box<[BuildNode; 2]>,
    },
}

impl BuildNode {
    fn bounds(&self) -> Aabb {
        match self {
            BuildNode::Leaf { bounds, .. } | BuildNode::Inner { bounds, .. } => *bounds,
        }
    }
}

/// A built subtree with its depth (nodes on its longest path) and number of inner nodes.
struct Subtree {
    node: BuildNode,
    depth: usize,
    inner: usize,
}

/// How a node is split.
#[derive(Clone, Copy, Debug)]
enum Split {
    /// Centroid bins `0..=bin` along `axis` go left.
    Sah { axis: usize, bin: usize },
    /// The smaller half of centroids along `axis` (ties by index) goes left.
    Median { axis: usize },
}

/// The build's primitives: each triangle's bounds and input index.
fn prims(triangles: &[[Vec3; 3]]) -> Vec<Prim> {
    triangles
        .iter()
        .enumerate()
        .map(|(i, &[a, b, c])| {
            let (a, b, c) = (Vec3A::from(a), Vec3A::from(b), Vec3A::from(c));
            Prim {
                bounds: Aabb {
                    lo: a.min(b).min(c),
                    hi: a.max(b).max(c),
                },
                index: i as u32,
            }
        })
        .collect()
}

impl Bvh {
    /// Builds the hierarchy over `triangles`, each given by its three corners in the world frame;
    /// `Hit::triangle` refers to positions in this slice (so at most `u32::MAX` triangles).
    /// Zero triangles give an empty hierarchy that nothing hits. Degenerate triangles are kept
    /// (rays almost never hit them); non-finite corners give unspecified hits but never a panic.
    /// Cost O(n log n), parallel over subtrees, identical for any thread count.
    pub fn new(triangles: &[[Vec3; 3]]) -> Bvh {
        if triangles.is_empty() {
            return Bvh::default();
        }
        let mut prims = prims(triangles);
        let tree = build(&mut prims, 0, 0);
        let mut nodes = Vec::with_capacity(tree.inner.div_ceil(2));
        let root = flatten(&tree.node, &mut nodes);
        let all = tree.node.bounds();
        Bvh {
            nodes,
            root,
            bounds: Some((Vec3::from(all.lo), Vec3::from(all.hi))),
            triangles: prims
                .iter()
                .map(|p| {
                    let [a, b, c] = triangles[p.index as usize];
                    [a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z]
                })
                .collect(),
            indices: prims.iter().map(|p| p.index).collect(),
            depth: tree.depth,
            binary_inner: tree.inner,
        }
    }

    /// The closest hit of either face with `t_min < t < t_max` (`t` in the ray's length unit),
    /// ties to the smallest triangle index; `u`, `v` are the barycentric weights of corners 1
    /// and 2. No allocation.
    pub fn closest_hit(&self, ray: &Ray, t_min: f32, t_max: f32) -> Option<Hit> {
        if self.indices.is_empty() {
            return None;
        }
        match dominant_axis(ray.direction) {
            0 => self.closest::<1, 2, 0>(ray, t_min, t_max),
            1 => self.closest::<2, 0, 1>(ray, t_min, t_max),
            _ => self.closest::<0, 1, 2>(ray, t_min, t_max),
        }
    }

    /// Whether any triangle is hit (either face) with `t_min < t < t_max`; stops at the first
    /// hit found (shadow rays). No allocation.
    pub fn occluded(&self, ray: &Ray, t_min: f32, t_max: f32) -> bool {
        let mut hint = OccluderHint::NONE;
        self.occluded_by(ray, t_min, t_max, &mut hint)
    }

    /// [`Bvh::occluded`], testing the triangle of `hint` first: the one that blocked an earlier,
    /// similar ray (a shadow cache: neighbouring shadow rays towards one light are mostly blocked
    /// by the same triangle, and one triangle test replaces the walk down the tree). A ray the
    /// tree finds blocked leaves its blocking triangle in `hint`; an open one leaves `hint` as
    /// it was. The answer is the same whatever the hint: the hinted triangle is tested with the
    /// same test and bounds as in the walk.
    pub fn occluded_by(&self, ray: &Ray, t_min: f32, t_max: f32, hint: &mut OccluderHint) -> bool {
        if self.indices.is_empty() {
            return false;
        }
        match dominant_axis(ray.direction) {
            0 => self.any::<1, 2, 0>(ray, t_min, t_max, hint),
            1 => self.any::<2, 0, 1>(ray, t_min, t_max, hint),
            _ => self.any::<0, 1, 2>(ray, t_min, t_max, hint),
        }
    }

    /// Bounds `(min, max)` of all triangles, world frame; `None` when empty.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        self.bounds
    }

    /// Number of triangles.
    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }

    /// The corners of every triangle, in input order (`Hit::triangle` indexes this list): what a
    /// rasteriser draws of the same geometry (the real-time viewer).
    pub fn triangles(&self) -> Vec<[Vec3; 3]> {
        let mut corners = vec![[Vec3::ZERO; 3]; self.indices.len()];
        for (&index, t) in self.indices.iter().zip(&self.triangles) {
            corners[index as usize] = [
                Vec3::new(t[0], t[1], t[2]),
                Vec3::new(t[3], t[4], t[5]),
                Vec3::new(t[6], t[7], t[8]),
            ];
        }
        corners
    }

    /// Number of nodes, inner and leaves, of the binary tree as built (0 when empty, 1 for a
    /// single leaf); the four-wide tree that queries walk has the same leaves.
    pub fn node_count(&self) -> usize {
        if self.indices.is_empty() {
            0
        } else {
            1 + 2 * self.binary_inner
        }
    }

    /// Nodes on the longest root-to-leaf path of the binary tree as built (0 when empty, 1 for
    /// a single leaf; at most 63); the four-wide tree's paths have at most half as many inner
    /// nodes.
    pub fn depth(&self) -> usize {
        self.depth
    }

    /// How a walk starts, before its triangle ray and traversal stack are made: `None` for a
    /// ray that misses all of the root's children within `cull` (most rays, past a small
    /// object: the walk stops at once); else the box ray for the walk, itself `None` for a
    /// root leaf (a ground plane's two triangles), whose triangles are tested directly,
    /// without the box ray's divisions.
    #[inline(always)]
    fn enter(&self, ray: &Ray, t_min: f32, cull: f32) -> Option<Option<BoxRay>> {
        if self.root.count != 0 {
            return Some(None);
        }
        let box_ray = BoxRay::new(ray, t_min);
        (box_ray.test(&self.nodes[self.root.child as usize], cull).0 != 0).then_some(Some(box_ray))
    }

    fn closest<const KX: usize, const KY: usize, const KZ: usize>(
        &self,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
    ) -> Option<Hit> {
        let mut best_t = t_max;
        let mut best: Option<(usize, TriangleHit)> = None;
        let mut best_index = u32::MAX;
        let mut cull = widen(best_t);
        let mut node = self.root;
        // Early outs ([`Bvh::enter`]) before the triangle ray and the traversal stack are made
        // (the stack is zeroed, 1.1 KiB: it was 3 % of a reference render).
        let box_ray = self.enter(ray, t_min, cull)?;
        let tri_ray = TriangleRay::<KX, KY, KZ>::new(ray);
        // The leaf `first..first + count` against the best hit so far.
        let mut test_leaf = |first: usize, count: usize, cull: &mut f32| {
            for k in first..first + count {
                let Some(h) = tri_ray.intersect(&self.triangles[k]) else {
                    continue;
                };
                if h.t > t_min
                    && h.t < t_max
                    && (h.t < best_t || (h.t == best_t && self.indices[k] < best_index))
                {
                    best_t = h.t;
                    best_index = self.indices[k];
                    best = Some((k, h));
                    *cull = widen(best_t);
                }
            }
        };
        match &box_ray {
            None => test_leaf(node.child as usize, node.count as usize, &mut cull),
            Some(box_ray) => {
                let mut stack = [(NodeRef::default(), 0.0f32); STACK_SIZE];
                let mut sp = 0;
                loop {
                    if node.count == 0 {
                        let quad = &self.nodes[node.child as usize];
                        let (mask, near) = box_ray.test(quad, cull);
                        if mask == 0 {
                            if !pop(&stack, &mut sp, &mut node, cull) {
                                break;
                            }
                            continue;
                        }
                        let rest = mask & (mask - 1);
                        if rest == 0 {
                            node = quad.get(mask.trailing_zeros() as usize);
                            continue;
                        }
                        if rest & (rest - 1) == 0 {
                            // Two: the nearer next, the other pushed.
                            let (a, b) = (mask.trailing_zeros(), rest.trailing_zeros());
                            let (a, b) = (a as usize, b as usize);
                            let (next, later) = if near[b] < near[a] { (b, a) } else { (a, b) };
                            stack[sp] = (quad.get(later), near[later]);
                            sp += 1;
                            node = quad.get(next);
                            continue;
                        }
                        // The nearest child next, the others pushed farthest first.
                        let (order, n) = far_to_near(mask, near);
                        for &i in &order[..n - 1] {
                            stack[sp] = (quad.get(i), near[i]);
                            sp += 1;
                        }
                        node = quad.get(order[n - 1]);
                        continue;
                    }
                    test_leaf(node.child as usize, node.count as usize, &mut cull);
                    if !pop(&stack, &mut sp, &mut node, cull) {
                        break;
                    }
                }
            }
        }
        best.map(|(k, h)| Hit {
            t: h.t,
            triangle: self.indices[k],
            u: h.v / h.det,
            v: h.w / h.det,
        })
    }

    fn any<const KX: usize, const KY: usize, const KZ: usize>(
        &self,
        ray: &Ray,
        t_min: f32,
        t_max: f32,
        hint: &mut OccluderHint,
    ) -> bool {
        let cull = widen(t_max);
        let mut node = self.root;
        // Early outs ([`Bvh::enter`]) before the triangle ray and the traversal stack (zeroed,
        // 768 bytes) are made.
        let Some(box_ray) = self.enter(ray, t_min, cull) else {
            return false;
        };
        let tri_ray = TriangleRay::<KX, KY, KZ>::new(ray);
        let hits = |tri: &[f32; 9]| {
            tri_ray
                .intersect(tri)
                .is_some_and(|h| h.t > t_min && h.t < t_max)
        };
        if let Some(tri) = self.triangles.get(hint.0 as usize)
            && hits(tri)
        {
            return true;
        }
        // The first triangle of `first..first + count` that blocks, noted in the hint.
        let mut blocked_in = |first: usize, count: usize| {
            let found = self.triangles[first..first + count].iter().position(hits);
            if let Some(k) = found {
                hint.0 = (first + k) as u32;
            }
            found.is_some()
        };
        let Some(box_ray) = box_ray else {
            return blocked_in(node.child as usize, node.count as usize);
        };
        let mut stack = [NodeRef::default(); STACK_SIZE];
        let mut sp = 0;
        loop {
            if node.count == 0 {
                let quad = &self.nodes[node.child as usize];
                let (mask, _) = box_ray.test(quad, cull);
                if mask == 0 {
                    if sp == 0 {
                        return false;
                    }
                    sp -= 1;
                    node = stack[sp];
                    continue;
                }
                // The first child entered next, the others (if any) pushed: any blocker ends
                // the walk, and ordering the children by distance cost more than it saved.
                let mut rest = mask & (mask - 1);
                node = quad.get(mask.trailing_zeros() as usize);
                while rest != 0 {
                    stack[sp] = quad.get(rest.trailing_zeros() as usize);
                    sp += 1;
                    rest &= rest - 1;
                }
                continue;
            }
            if blocked_in(node.child as usize, node.count as usize) {
                return true;
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            node = stack[sp];
        }
    }
}

/// The triangle that blocked an earlier shadow ray ([`Bvh::occluded_by`]): a position in one
/// BVH's leaf order, meaningful for that BVH only.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OccluderHint(u32);

impl OccluderHint {
    /// No triangle yet.
    pub const NONE: OccluderHint = OccluderHint(u32::MAX);
}

impl Default for OccluderHint {
    fn default() -> Self {
        OccluderHint::NONE
    }
}

/// Builds the subtree over `prims`, whose first element is at `first` in leaf order.
fn build(prims: &mut [Prim], first: usize, depth: usize) -> Subtree {
    let n = prims.len();
    let (bounds, centroids) = prims.iter().fold((Aabb::EMPTY, Aabb::EMPTY), |(b, c), p| {
        (b.union(p.bounds), c.grow(p.centroid2()))
    });
    let leaf = BuildNode::Leaf {
        bounds,
        first: first as u32,
        count: n as u32,
    };
    if n <= MAX_LEAF {
        return Subtree {
            node: leaf,
            depth: 1,
            inner: 0,
        };
    }
    let median = Split::Median {
        axis: widest_axis(centroids),
    };
    let split = if depth >= SAH_MAX_DEPTH {
        median
    } else {
        sah_split(prims, centroids).unwrap_or(median)
    };
    let mut mid = partition(prims, split, centroids);
    if mid == 0 || mid == n {
        // Unreachable for an SAH plane with triangles on both sides; kept so that no float
        // surprise can ever produce an empty child.
        mid = partition(prims, median, centroids);
    }
    let (left, right) = prims.split_at_mut(mid);
    let (a, b) = if n >= PARALLEL_MIN {
        rayon::join(
            || build(left, first, depth + 1),
            || build(right, first + mid, depth + 1),
        )
    } else {
        (
            build(left, first, depth + 1),
            build(right, first + mid, depth + 1),
        )
    };
    Subtree {
        depth: 1 + a.depth.max(b.depth),
        inner: 1 + a.inner + b.inner,
        node: BuildNode::Inner {
            bounds,
            children: Box::new([a.node, b.node]),
        },
    }
}

/// The axis along which the centroid bounds are widest (the first on ties).
fn widest_axis(centroids: Aabb) -> usize {
    let e = centroids.hi - centroids.lo;
    if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    }
}

/// Per axis, the factor that maps a centroid offset from `centroids.lo` to a bin (0 on axes
/// where the centroids do not spread or the spread is not finite: everything in bin 0).
fn bin_scale(centroids: Aabb) -> Vec3A {
    let e = centroids.hi - centroids.lo;
    Vec3A::from_array(e.to_array().map(|e| {
        if e > 0.0 && e.is_finite() {
            BINS as f32 / e
        } else {
            0.0
        }
    }))
}

/// Bin coordinates of a (doubled) centroid, in `[0, BINS - 1]` (a NaN goes to the last bin).
fn bin_coordinates(c: Vec3A, lo: Vec3A, scale: Vec3A) -> [f32; 3] {
    ((c - lo) * scale)
        .min(Vec3A::splat((BINS - 1) as f32))
        .to_array()
}

/// The binned SAH plane of least cost `n_L A(L) + n_R A(R)` over the three axes (the node's own
/// traversal cost is the same for every plane), `None` when no plane has triangles on both
/// sides. Ties go to the first axis, then the lowest plane.
fn sah_split(prims: &[Prim], centroids: Aabb) -> Option<Split> {
    let scale = bin_scale(centroids);
    let mut bins = [[(Aabb::EMPTY, 0u32); BINS]; 3];
    for p in prims {
        let b = bin_coordinates(p.centroid2(), centroids.lo, scale);
        for (bins, b) in bins.iter_mut().zip(b) {
            let bin = &mut bins[b as usize];
            bin.0 = bin.0.union(p.bounds);
            bin.1 += 1;
        }
    }
    let mut best: Option<(f32, Split)> = None;
    for (axis, bins) in bins.iter().enumerate() {
        // Plane i puts bins 0..=i on the left.
        let mut right_cost = [0.0f32; BINS - 1];
        let mut right_count = [0u32; BINS - 1];
        let (mut acc, mut count) = (Aabb::EMPTY, 0u32);
        for i in (1..BINS).rev() {
            acc = acc.union(bins[i].0);
            count += bins[i].1;
            right_cost[i - 1] = acc.half_area() * count as f32;
            right_count[i - 1] = count;
        }
        let (mut acc, mut count) = (Aabb::EMPTY, 0u32);
        for i in 0..BINS - 1 {
            acc = acc.union(bins[i].0);
            count += bins[i].1;
            if count == 0 || right_count[i] == 0 {
                continue;
            }
            let cost = acc.half_area() * count as f32 + right_cost[i];
            if best.is_none_or(|(c, _)| cost < c) {
                best = Some((cost, Split::Sah { axis, bin: i }));
            }
        }
    }
    best.map(|(_, split)| split)
}

/// Reorders `prims` so the left side of `split` comes first; returns the left count.
fn partition(prims: &mut [Prim], split: Split, centroids: Aabb) -> usize {
    match split {
        Split::Sah { axis, bin } => {
            let scale = bin_scale(centroids);
            let left = |p: &Prim| {
                bin_coordinates(p.centroid2(), centroids.lo, scale)[axis] as usize <= bin
            };
            let (mut i, mut j) = (0, prims.len());
            while i < j {
                if left(&prims[i]) {
                    i += 1;
                } else {
                    j -= 1;
                    prims.swap(i, j);
                }
            }
            i
        }
        Split::Median { axis } => {
            let mid = prims.len() / 2;
            prims.select_nth_unstable_by(mid, |a, b| {
                a.centroid2()[axis]
                    .total_cmp(&b.centroid2()[axis])
                    .then(a.index.cmp(&b.index))
            });
            mid
        }
    }
}

/// Writes the four-wide nodes below `node` depth first and returns its reference.
fn flatten(node: &BuildNode, nodes: &mut Vec<QuadNode>) -> NodeRef {
    match node {
        BuildNode::Leaf { first, count, .. } => NodeRef {
            child: *first,
            count: *count,
        },
        BuildNode::Inner { .. } => {
            let slot = nodes.len();
            nodes.push(QuadNode::new(&[]));
            let children = quad_children(node);
            let refs: Vec<(Aabb, NodeRef)> = children
                .iter()
                .map(|c| (c.bounds(), flatten(c, nodes)))
                .collect();
            nodes[slot] = QuadNode::new(&refs);
            NodeRef {
                child: slot as u32,
                count: 0,
            }
        }
    }
}

/// The children of inner binary node `node` in the four-wide tree: its grandchildren where its
/// children are inner, the leaf children themselves; with three, the inner one of largest area
/// is opened in turn (the first on ties). Every inner node of the four-wide tree therefore
/// sits at least two binary levels below its parent, which bounds the traversal stack.
fn quad_children(node: &BuildNode) -> Vec<&BuildNode> {
    // An inner node's two children in place of it, a leaf itself.
    fn open<'a>(n: &'a BuildNode, out: &mut Vec<&'a BuildNode>) {
        match n {
            BuildNode::Inner { children, .. } => out.extend(children.iter()),
            BuildNode::Leaf { .. } => out.push(n),
        }
    }
    let mut children = Vec::with_capacity(4);
    if let BuildNode::Inner { children: two, .. } = node {
        two.iter().for_each(|c| open(c, &mut children));
    }
    if children.len() == 3 {
        let mut widest: Option<(usize, f32)> = None;
        for (i, c) in children.iter().enumerate() {
            let area = c.bounds().half_area();
            if matches!(c, BuildNode::Inner { .. }) && widest.is_none_or(|(_, a)| area > a) {
                widest = Some((i, area));
            }
        }
        if let Some((i, _)) = widest
            && let BuildNode::Inner { children: two, .. } = children.remove(i)
        {
            children.splice(i..i, two.iter());
        }
    }
    children
}

/// Pops the next stack entry not farther than `cull` into `node`; false when none is left.
fn pop(stack: &[(NodeRef, f32)], sp: &mut usize, node: &mut NodeRef, cull: f32) -> bool {
    while *sp > 0 {
        *sp -= 1;
        let (next, near) = stack[*sp];
        if near <= cull {
            *node = next;
            return true;
        }
    }
    false
}

/// `t` moved away from zero by [`WIDEN`] of its magnitude.
fn widen(t: f32) -> f32 {
    t + t.abs() * WIDEN
}

/// The axis of the largest direction component (the watertight test's `k_z`).
fn dominant_axis(d: Vec3) -> usize {
    let a = d.abs();
    if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    }
}

/// A ray prepared for slab tests against four-wide nodes.
struct BoxRay {
    origin: [Vec4; 3],
    inv_dir: [Vec4; 3],
    /// Per axis, which of a node's corners (0: lower, 1: upper) the ray meets first: the lower
    /// one where the direction component is positive (or +0).
    near_side: [usize; 3],
    t_min: Vec4,
}

impl BoxRay {
    fn new(ray: &Ray, t_min: f32) -> Self {
        let o = ray.origin;
        // 1/0 = inf would give 0 * inf = NaN on a slab plane through the origin; a finite
        // `f32::MAX` gives 0 there and +-inf (never NaN) elsewhere.
        let inv = (Vec3::ONE / ray.direction).clamp(Vec3::splat(-f32::MAX), Vec3::splat(f32::MAX));
        let side = |v: f32| usize::from(v.is_sign_negative());
        BoxRay {
            origin: [Vec4::splat(o.x), Vec4::splat(o.y), Vec4::splat(o.z)],
            inv_dir: [Vec4::splat(inv.x), Vec4::splat(inv.y), Vec4::splat(inv.z)],
            near_side: [side(inv.x), side(inv.y), side(inv.z)],
            t_min: Vec4::splat(t_min),
        }
    }

    /// Which of the four children the ray enters within `[t_min, t_hi]` (bit `i`: child `i`)
    /// and their entry distances, lane by lane. Per axis the near plane's distance is the
    /// smaller of the two (the inverse direction's sign orders them), so the values are those
    /// of `min`/`max` over both planes; an empty box's near distance is `+inf` and its far
    /// one `-inf` on every axis, never entered.
    #[inline(always)]
    fn test(&self, node: &QuadNode, t_hi: f32) -> (u32, Vec4) {
        let slab = |axis: usize| {
            let s = self.near_side[axis];
            let near = (node.bounds[s][axis] - self.origin[axis]) * self.inv_dir[axis];
            let far = (node.bounds[1 - s][axis] - self.origin[axis]) * self.inv_dir[axis];
            (near, far)
        };
        let (nx, fx) = slab(0);
        let (ny, fy) = slab(1);
        let (nz, fz) = slab(2);
        let near = nx.max(ny).max(nz).max(self.t_min);
        // A zero direction component gives `far = -inf` for a slab the ray runs beside; widening
        // that would make `-inf + inf = NaN`, which `min` turns into `t_hi`, so the node would
        // never be culled. Finite values are unchanged.
        let far = fx.min(fy).min(fz).max(Vec4::splat(-f32::MAX));
        let far = (far + far.abs() * WIDEN).min(Vec4::splat(t_hi));
        (near.cmple(far).bitmask(), near)
    }
}

/// The children set in `mask` (bit `i`: child `i`), farthest first by their entry distance
/// `near` (ties by child order), and how many there are.
#[inline(always)]
fn far_to_near(mask: u32, near: Vec4) -> ([usize; 4], usize) {
    let mut order = [0usize; 4];
    let mut n = 0;
    for i in 0..4 {
        if mask >> i & 1 == 1 {
            order[n] = i;
            n += 1;
        }
    }
    for a in 1..n {
        let mut b = a;
        while b > 0 && near[order[b - 1]] < near[order[b]] {
            order.swap(b - 1, b);
            b -= 1;
        }
    }
    (order, n)
}

/// A ray prepared for the watertight triangle test: `k_z = KZ` is the dominant axis, the shear
/// `(S_x, S_y, S_z) = (d_kx / d_kz, d_ky / d_kz, 1 / d_kz)`.
struct TriangleRay<const KX: usize, const KY: usize, const KZ: usize> {
    origin: [f32; 3],
    shear: [f32; 3],
}

/// A triangle hit: distance and the unnormalised edge functions of corners 1 and 2 with their
/// sum `det`.
#[derive(Clone, Copy, Debug)]
struct TriangleHit {
    t: f32,
    v: f32,
    w: f32,
    det: f32,
}

impl<const KX: usize, const KY: usize, const KZ: usize> TriangleRay<KX, KY, KZ> {
    fn new(ray: &Ray) -> Self {
        let d = ray.direction.to_array();
        TriangleRay {
            origin: ray.origin.to_array(),
            shear: [d[KX] / d[KZ], d[KY] / d[KZ], 1.0 / d[KZ]],
        }
    }

    /// The two-sided watertight test; `None` on a miss or when `t` is not certainly positive
    /// (at most its rounding-error bound), otherwise `t` along the ray.
    #[inline(always)]
    fn intersect(&self, tri: &[f32; 9]) -> Option<TriangleHit> {
        let o = &self.origin;
        let [sx, sy, sz] = self.shear;
        let az = tri[KZ] - o[KZ];
        let bz = tri[3 + KZ] - o[KZ];
        let cz = tri[6 + KZ] - o[KZ];
        let ax = (tri[KX] - o[KX]) - sx * az;
        let ay = (tri[KY] - o[KY]) - sy * az;
        let bx = (tri[3 + KX] - o[KX]) - sx * bz;
        let by = (tri[3 + KY] - o[KY]) - sy * bz;
        let cx = (tri[6 + KX] - o[KX]) - sx * cz;
        let cy = (tri[6 + KY] - o[KY]) - sy * cz;
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let f = f64::from;
            u = (f(cx) * f(by) - f(cy) * f(bx)) as f32;
            v = (f(ax) * f(cy) - f(ay) * f(cx)) as f32;
            w = (f(bx) * f(ay) - f(by) * f(ax)) as f32;
        }
        let negative = (u < 0.0) | (v < 0.0) | (w < 0.0);
        let positive = (u > 0.0) | (v > 0.0) | (w > 0.0);
        if negative & positive {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t = sz * (u * az + v * bz + w * cz) / det;
        // Behind the origin (a shadow ray's own surface, most often): no hit whatever the bound.
        if t <= 0.0 || t.is_nan() {
            return None;
        }
        // Only hits certainly in front of the origin: `t` above its own rounding-error bound
        // (pbrt-v4 section 6.8.4, in this test's variables, with the shear terms weighted by the
        // shear factors, which pbrt bounds by 1).
        let max_z = az.abs().max(bz.abs()).max(cz.abs());
        let max_zt = sz.abs() * max_z;
        let max_x = ax.abs().max(bx.abs()).max(cx.abs());
        let max_y = ay.abs().max(by.abs()).max(cy.abs());
        let delta_x = gamma(5) * (max_x + sx.abs() * max_z);
        let delta_y = gamma(5) * (max_y + sy.abs() * max_z);
        let delta_e = 2.0 * (gamma(2) * max_x * max_y + delta_y * max_x + delta_x * max_y);
        let max_e = u.abs().max(v.abs()).max(w.abs());
        let delta_t = 3.0
            * (gamma(3) * max_e * max_zt + delta_e * max_zt + gamma(3) * max_zt * max_e)
            / det.abs();
        // NaN `t` (a degenerate triangle) is no hit either.
        (t > delta_t).then_some(TriangleHit { t, v, w, det })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_pcg::Pcg64;

    fn soup(n: usize, seed: u64) -> Vec<[Vec3; 3]> {
        let mut rng = Pcg64::seed_from_u64(seed);
        let mut p = || Vec3::new(rng.random(), rng.random(), rng.random());
        (0..n)
            .map(|_| {
                let c = p() * 10.0;
                [c, c + p() - 0.5, c + p() - 0.5]
            })
            .collect()
    }

    #[test]
    fn quad_node_is_two_cache_lines() {
        assert_eq!(std::mem::size_of::<QuadNode>(), 128);
        assert_eq!(std::mem::align_of::<QuadNode>(), 64);
    }

    /// 120 triangles, each twice as far along +X as the previous one: the SAH peels a few off
    /// per level, far deeper than log2(n).
    fn exponentially_spaced() -> Vec<[Vec3; 3]> {
        (0..120)
            .map(|i| {
                let x = 2f32.powi(i);
                [
                    Vec3::new(x, 0.0, 0.0),
                    Vec3::new(x, 1.0, 0.0),
                    Vec3::new(x, 0.0, 1.0),
                ]
            })
            .collect()
    }

    /// The slots of `q` that hold a child (an unused one has the empty box).
    fn used_slots(q: &QuadNode) -> impl Iterator<Item = usize> + '_ {
        (0..4).filter(|&i| q.bounds[0][0][i] <= q.bounds[1][0][i])
    }

    /// Four-wide inner nodes on the longest path from `r` down.
    fn quad_depth(bvh: &Bvh, r: NodeRef) -> usize {
        if r.count > 0 {
            return 0;
        }
        let q = &bvh.nodes[r.child as usize];
        1 + used_slots(q)
            .map(|i| quad_depth(bvh, q.get(i)))
            .max()
            .unwrap_or(0)
    }

    #[test]
    fn four_wide_paths_have_at_most_half_the_binary_inner_nodes() {
        // Well-spread triangles, and the deep SAH tree of exponentially spaced ones.
        for tris in [soup(5000, 2), exponentially_spaced()] {
            let bvh = Bvh::new(&tris);
            let quads = quad_depth(&bvh, bvh.root);
            assert!(
                quads >= 1 && quads <= (bvh.depth() - 1).div_ceil(2),
                "{quads} {}",
                bvh.depth()
            );
            assert!(3 * quads <= STACK_SIZE);
        }
    }

    #[test]
    fn build_is_identical_for_any_thread_count() {
        let tris = soup(20_000, 7);
        let with = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| Bvh::new(&tris))
        };
        let (one, many) = (with(1), with(4));
        assert_eq!(one.nodes, many.nodes);
        assert_eq!(one.root, many.root);
        assert_eq!(one.indices, many.indices);
        assert_eq!(one.triangles, many.triangles);
        assert_eq!(one.depth, many.depth);
    }

    #[test]
    fn triangles_come_back_in_input_order() {
        let tris = soup(500, 3);
        assert_eq!(Bvh::new(&tris).triangles(), tris);
        assert!(Bvh::new(&[]).triangles().is_empty());
    }

    #[test]
    fn leaves_hold_at_most_four_triangles_in_leaf_order() {
        let tris = soup(5000, 3);
        let bvh = Bvh::new(&tris);
        let mut seen = vec![false; tris.len()];
        let mut stack = vec![bvh.root];
        let mut next_first = 0;
        let mut leaves = Vec::new();
        while let Some(r) = stack.pop() {
            if r.count == 0 {
                let q = &bvh.nodes[r.child as usize];
                let children: Vec<NodeRef> = used_slots(q).map(|i| q.get(i)).collect();
                assert!((2..=4).contains(&children.len()));
                stack.extend(children.into_iter().rev());
            } else {
                leaves.push(r);
            }
        }
        let leaf_count = leaves.len();
        for r in leaves {
            assert!((1..=MAX_LEAF as u32).contains(&r.count));
            assert_eq!(
                r.child, next_first,
                "leaves are contiguous in depth-first order"
            );
            next_first += r.count;
            for k in r.child..r.child + r.count {
                seen[bvh.indices[k as usize] as usize] = true;
            }
        }
        assert!(seen.iter().all(|&s| s));
        assert_eq!(bvh.node_count(), 2 * (leaf_count - 1) + 1);
    }

    #[test]
    fn child_boxes_contain_their_triangles() {
        let tris = soup(3000, 11);
        let bvh = Bvh::new(&tris);
        fn check(bvh: &Bvh, r: NodeRef, lo: Vec3, hi: Vec3) {
            if r.count > 0 {
                for k in r.child..r.child + r.count {
                    let t = bvh.triangles[k as usize];
                    for c in t.chunks(3) {
                        let p = Vec3::from_slice(c);
                        assert!(p.cmpge(lo).all() && p.cmple(hi).all());
                    }
                }
                return;
            }
            let q = &bvh.nodes[r.child as usize];
            for i in used_slots(q) {
                let [x, y, z] = q.bounds[0];
                let clo = Vec3::new(x[i], y[i], z[i]);
                let [x, y, z] = q.bounds[1];
                let chi = Vec3::new(x[i], y[i], z[i]);
                assert!(clo.cmpge(lo).all() && chi.cmple(hi).all());
                check(bvh, q.get(i), clo, chi);
            }
        }
        let (lo, hi) = bvh.bounds().unwrap();
        check(&bvh, bvh.root, lo, hi);
    }

    #[test]
    fn sah_depth_stays_bounded_on_exponentially_spaced_triangles() {
        let tris = exponentially_spaced();
        let bvh = Bvh::new(&tris);
        assert!(bvh.depth() > 20, "the SAH goes deep here: {}", bvh.depth());
        assert!(bvh.depth() <= MAX_DEPTH, "depth {}", bvh.depth());
        // Every triangle is still found: rays along +X at y = z = 0.25 hit the next one ahead.
        for i in [0, 1, 60, 119] {
            let x = if i == 0 { 0.0 } else { 2f32.powi(i) * 0.75 };
            let ray = Ray::new(Vec3::new(x, 0.25, 0.25), Vec3::X);
            let hit = bvh.closest_hit(&ray, 0.0, f32::INFINITY).unwrap();
            assert_eq!(hit.triangle as i32, i);
        }
    }

    #[test]
    fn below_the_sah_depth_limit_median_splits_halve_the_count() {
        let tris = soup(10_000, 5);
        let mut prims = prims(&tris);
        // 10000 -> 5000 -> ... -> 10 -> 5 -> 3: 12 splits, 13 nodes on every path.
        let tree = build(&mut prims, 0, SAH_MAX_DEPTH);
        assert_eq!(tree.depth, 13);
        // The worst case: 2^32 - 1 triangles below the limit end in leaves within the stack.
        let (mut n, mut depth) = (u64::from(u32::MAX), SAH_MAX_DEPTH);
        while n > MAX_LEAF as u64 {
            n = n.div_ceil(2);
            depth += 1;
        }
        assert!(depth < MAX_DEPTH, "deepest leaf at depth {depth}");
    }

    #[test]
    fn slab_test_handles_zero_direction_components() {
        // A ray along -Z lying exactly in the plane x = 0 of a box face, and one in the plane of
        // both x = 0 and y = 0 faces: 0 * inv must not be NaN.
        let a = Aabb {
            lo: Vec3A::ZERO,
            hi: Vec3A::ONE,
        };
        let b = Aabb {
            lo: Vec3A::splat(5.0),
            hi: Vec3A::splat(6.0),
        };
        let quad = QuadNode::new(&[(a, NodeRef::default()), (b, NodeRef::default())]);
        for origin in [Vec3::new(0.0, 0.5, 3.0), Vec3::new(0.0, 0.0, 3.0)] {
            let ray = BoxRay::new(&Ray::new(origin, Vec3::NEG_Z), 0.0);
            let (mask, near) = ray.test(&quad, f32::INFINITY);
            assert_eq!(mask, 1, "the two unused slots are never entered");
            assert!((near.x - 2.0).abs() < 1e-6, "{near}");
        }
        // Beside the slab with a zero component: a miss, not NaN. Far beside it on the negative
        // side both plane distances overflow to -inf (the case that must not widen to NaN).
        for x in [-0.1, 1.1, 2.5, 300.0] {
            let ray = BoxRay::new(&Ray::new(Vec3::new(x, 0.5, 3.0), Vec3::NEG_Z), 0.0);
            assert_eq!(ray.test(&quad, f32::INFINITY).0, 0, "x = {x}");
        }
    }

    #[test]
    fn edge_functions_fall_back_to_f64_on_exact_zero() {
        // A ray exactly through the shared edge of two triangles hits one of them.
        let tris = [
            [Vec3::ZERO, Vec3::X, Vec3::Y],
            [Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y],
        ];
        let bvh = Bvh::new(&tris);
        let ray = Ray::new(Vec3::new(0.25, 0.75, 1.0), Vec3::NEG_Z);
        let hit = bvh.closest_hit(&ray, 0.0, f32::INFINITY).unwrap();
        assert_eq!(hit.triangle, 0, "tie at t = 1 goes to the smaller index");
        assert!((hit.t - 1.0).abs() < 1e-6);
    }
}
