// Reading the lights' caster cells (caster_cells.rs); prepended to light_tiles.wgsl, which
// binds the cells as `caster_cells: array<f32>` (storage).
// Per light, a CASTER_GRID x CASTER_GRID grid over its virtual tile and its min-pyramid,
// CASTER_CELLS in all: each cell holds the nearest depth (world units from the tile's near
// plane) that a caster drawn into the cell can have.

const CASTER_GRID: u32 = 32u;
const CASTER_LEVELS: u32 = 6u;
const CASTER_CELLS: u32 = 1365u;

// First cell of pyramid level `level` within a light's cells (caster_cells.rs's level_offset).
fn level_offset(level: u32) -> u32 {
    return ((1u << (2u * CASTER_LEVELS)) - (1u << (2u * (CASTER_LEVELS - level)))) / 3u;
}

// Whether a cell of light i's caster cells overlapping the rectangle [low, high] of its virtual
// tile (tile coordinates, x and y in [-1, 1]) holds a depth in front of `deepest` (world units
// from the tile's near plane), read at the pyramid level whose cells are at least `1 / parts`
// of the rectangle's width: at most (parts + 1)^2 cells. Conservative: false means no caster
// drawn into the tile's atlas can lie there in front of `deepest`.
fn caster_within(i: u32, low: vec2<f32>, high: vec2<f32>, deepest: f32, parts: f32) -> bool {
    let lo = max(low, vec2<f32>(-1.0));
    let hi = min(high, vec2<f32>(1.0));
    if any(lo > hi) {
        return false;
    }
    let width = 0.5 * f32(CASTER_GRID) * max(hi.x - lo.x, hi.y - lo.y);
    let level = min(u32(ceil(log2(max(width / parts, 1.0)))), CASTER_LEVELS - 1u);
    let n = CASTER_GRID >> level;
    let last = vec2<f32>(f32(n - 1u));
    let c0 = vec2<u32>(clamp(floor((lo + 1.0) * (0.5 * f32(n))), vec2<f32>(0.0), last));
    let c1 = vec2<u32>(clamp(floor((hi + 1.0) * (0.5 * f32(n))), vec2<f32>(0.0), last));
    let base = i * CASTER_CELLS + level_offset(level);
    var found = false;
    for (var y = c0.y; y <= c1.y; y = y + 1u) {
        for (var x = c0.x; x <= c1.x; x = x + 1u) {
            found = found || caster_cells[base + y * n + x] < deepest;
        }
    }
    return found;
}
