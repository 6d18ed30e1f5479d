use std::path::PathBuf;
use glam::{Mat3, Vec3};
use ibl_core::{Image, LatLong, Rgb};
use ibl_io::{WriteOptions, read_image, write_image};
use ibl_outdoor::courtyard::Courtyard;
use ibl_outdoor::synthetic::{SyntheticDay, map_error};
use ibl_outdoor::tracking::SkyTracker;
use ibl_outdoor::{CaptureSource, MapSettings, ProbeMaps, Relighter, SkyModel};

fn cached(name: &str, f: impl FnOnce() -> Image<Rgb>) -> Image<Rgb> {
    let p = PathBuf::from(format!("/tmp/odiag/{name}.pfm"));
    if let Ok(l) = read_image(&p) { return l.image; }
    let t = std::time::Instant::now();
    let im = f();
    eprintln!("rendered {name} in {:.1} s", t.elapsed().as_secs_f64());
    write_image(&p, &im, &WriteOptions::default()).unwrap();
    im
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let bounces: u32 = a.get(1).and_then(|s| s.parse().ok()).unwrap_or(1);
    let pspp: u32 = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(64);
    let tspp: u32 = a.get(3).and_then(|s| s.parse().ok()).unwrap_or(64);
    let env: u32 = a.get(5).and_then(|s| s.parse().ok()).unwrap_or(1024);
    let ks: Vec<usize> = a.get(6).map(|s| s.split(',').map(|v| v.parse().unwrap()).collect()).unwrap_or(vec![0, 6, 12, 13, 15]);
    let day = SyntheticDay { bounces, probe_spp: pspp, environment_width: env, ..SyntheticDay::standard() };
    let tday = SyntheticDay { bounces, probe_spp: tspp, environment_width: env, ..SyntheticDay::standard() };
    let e = if env == 1024 { String::new() } else { format!("_e{env}") };
    let yard = Courtyard::new(day.frame_size);
    let capture = day.frame_truth(0).unwrap();
    let probe = cached(&format!("b{bounces}_p{pspp}_k0_s1{e}"), || day.render_probe(&yard, &capture, 1).unwrap());
    let side: usize = a.get(4).and_then(|s| s.parse().ok()).unwrap_or(2);
    let settings = MapSettings { sky_model: SkyModel::Preetham { turbidity: 3.0 }, footprint_side: side, interreflection: ibl_outdoor::Interreflection::Off, ..MapSettings::default() };
    let sun0 = Vec3::from_array(capture.parameters.sun_direction);
    let maps = ProbeMaps::build(&yard.layer, &probe, yard.probe_position, Mat3::IDENTITY, sun0, CaptureSource::Measured, settings).unwrap();
    let layer = &yard.layer;
    let view = &maps.projection().view;
    let (w, h) = maps.size();
    let omega = LatLong::new(w, h).row_solid_angles();
    {
        let mut sky0 = SkyTracker::new(settings.sky_model, settings.transfer_bands, 0.0);
        sky0.update(sun0).unwrap();
        let shape0 = sky0.shape().unwrap().clone();
        let pa0 = Rgb::from_array(maps.capture().sky);
        let (mut n, mut sa, mut sc, mut sp, mut sd) = (0, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let mut ratios = Vec::new();
        let mut by_mesh = std::collections::BTreeMap::<String, [f64; 4]>::new();
        for (kk, &p) in maps.surface_pixels().iter().enumerate() {
            if maps.capture_sun_terms()[kk] > 0.0 || kk % 7 != 0 { continue; }
            let Some(a) = maps.albedo()[kk] else { continue };
            let hit = view.hits()[p].unwrap();
            let s = layer.surfaces[hit.triangle as usize];
            let d = layer.materials[s.material as usize].diffuse_albedo();
            let pt = maps.points()[kk];
            let c_sh = maps.transfer().sky_ambient(kk, &shape0).g as f64;
            let c_dir = ibl_outdoor::transfer::sky_ambient_direct(layer, pt, &shape0, 4096, kk as u64).g as f64;
            let obs = maps.probe().pixels()[p].g as f64;
            let r = obs / (d.g as f64 * c_dir * pa0.g as f64) - 1.0;
            ratios.push(r);
            if r > 1.0 {
                // Penumbra test: shadow rays to directions within 1 degree of the sun.
                let mut lit = 0;
                let (t1, t2) = ibl_scene::primitives::tangents(sun0);
                for a in 0..8 { let ang = a as f32 * std::f32::consts::TAU / 8.0; let dir = (sun0 + 0.0175 * (t1 * ang.cos() + t2 * ang.sin())).normalize();
                    let off = ibl_outdoor::transfer::ray_offset(layer);
                    if !layer.bvh.occluded(&ibl_scene::Ray::new(pt.position + pt.normal * off, dir), 0.0, f32::INFINITY) { lit += 1; } }
                println!("   tail: {} at {:?} n {:?} P/model {:+.0} %, lit within 1 deg: {lit}/8, n.l {:.3}", layer.object_names[s.object as usize], pt.position, pt.normal, 100.0 * r, pt.normal.dot(sun0));
            }
            n += 1;
            sa += a.g as f64 / d.g as f64 - 1.0;
            sc += c_sh / c_dir - 1.0;
            sp += obs / (d.g as f64 * c_dir * pa0.g as f64) - 1.0;
            sd += c_dir;
            let on = &layer.object_names[s.object as usize]; let name = if on.starts_with("tile") { "tiles".to_string() } else { on.clone() };
            let e = by_mesh.entry(name).or_default();
            e[0] += 1.0; e[1] += a.g as f64 / d.g as f64 - 1.0; e[2] += c_sh / c_dir - 1.0; e[3] += obs / (d.g as f64 * c_dir * pa0.g as f64) - 1.0;
        }
        let n = n as f64;
        println!("capture-shaded pixels ({n}): albedo bias {:+.2} %, c_sh/c_direct {:+.2} %, P/(d c_direct Pa) {:+.2} %, mean c {:.3}", 100.0*sa/n, 100.0*sc/n, 100.0*sp/n, sd/n);
        ratios.sort_by(f64::total_cmp);
        let q = |f: f64| 100.0 * ratios[((ratios.len() - 1) as f64 * f) as usize];
        println!("   P/model percentiles: 10 % {:+.1}, 25 % {:+.1}, 50 % {:+.1}, 75 % {:+.1}, 90 % {:+.1}, 99 % {:+.1}", q(0.1), q(0.25), q(0.5), q(0.75), q(0.9), q(0.99));
        for (m, e) in by_mesh { if e[0] > 5.0 { println!("   {m:24} n {:5} albedo {:+6.2} %  c_sh/c_dir {:+6.2} %  P/model {:+6.2} %", e[0], 100.0*e[1]/e[0], 100.0*e[2]/e[0], 100.0*e[3]/e[0]); } }
    }
    for k in ks {
        let truth = day.frame_truth(k).unwrap();
        let t = truth.parameters;
        let sun = Vec3::from_array(t.sun_direction);
        let want = cached(&format!("b{bounces}_p{tspp}_k{k}_s{}{e}", 1000 + k), || tday.render_probe(&yard, &truth, 1000 + k as u64).unwrap());
        let twin = cached(&format!("b{bounces}_p{tspp}_k{k}_s{}{e}", 2000 + k), || tday.render_probe(&yard, &truth, 2000 + k as u64).unwrap());
        let mut sky = SkyTracker::new(settings.sky_model, settings.transfer_bands, 0.0);
        sky.update(sun).unwrap();
        let mut rl = Relighter::new(&maps, 0.0);
        rl.update(layer, &maps, &sky, sun).unwrap();
        let (pa, pd) = (Rgb::from_array(t.sky), Rgb::from_array(t.sun));
        let relit = rl.relight(&maps, sun, pa, pd).unwrap();
        let lt = rl.lighting();
        // Relit with the true albedo.
        let mut ideal = relit.clone();
        for (kk, &p) in maps.surface_pixels().iter().enumerate() {
            let hit = view.hits()[p].unwrap();
            let s = layer.surfaces[hit.triangle as usize];
            let d = layer.materials[s.material as usize].diffuse_albedo();
            ideal.pixels_mut()[p] = d * (lt.sky_terms()[kk] * pa + pd * lt.sun_term(kk, sun));
        }
        // Oracle: edge pixels (a 4-neighbour is sky or of another normal) take the truth.
        let is_edge = |p: usize| -> bool {
            let (i, j) = (p % w, p / w);
            let Some(hc) = view.hits()[p] else { return false };
            [((i + 1) % w, j), ((i + w - 1) % w, j), (i, j.saturating_sub(1)), (i, (j + 1).min(h - 1))].iter().any(|&(a, b)| match view.hits()[b * w + a] { None => true, Some(o) => o.normal.dot(hc.normal) < 0.999 })
        };
        let mut oracle = relit.clone();
        let mut edges = 0;
        for p in 0..w * h { if is_edge(p) { oracle.pixels_mut()[p] = want.pixels()[p]; edges += 1; } }
        println!("   edge pixels {edges}: relit with edges from the truth {:.2} %", map_error(&oracle, &want, sun, 4));
        let mut sky_edges = 0;
        for p in 0..w * h {
            let (i, j) = (p % w, p / w);
            if view.hits()[p].is_none() && [((i + 1) % w, j), ((i + w - 1) % w, j), (i, j.saturating_sub(1)), (i, (j + 1).min(h - 1))].iter().any(|&(a, b)| view.hits()[b * w + a].is_some()) { oracle.pixels_mut()[p] = want.pixels()[p]; sky_edges += 1; }
        }
        println!("   and {sky_edges} sky pixels next to surfaces too: {:.2} %", map_error(&oracle, &want, sun, 4));
        println!("k {k:2} sun elev {:.1}: relit(true light) {:.2} %, true-albedo {:.2} %, floor {:.2} %",
            sun.y.asin().to_degrees(), map_error(&relit, &want, sun, 4), map_error(&ideal, &want, sun, 4), map_error(&twin, &want, sun, 4));
        // Category breakdown (per pixel, green): signed and abs error, sum of truth.
        let mut cats = std::collections::BTreeMap::<&str, [f64; 4]>::new();
        let mut total = 0.0;
        for p in 0..w * h {
            let j = p / w;
            let o = omega[j];
            let g = relit.pixels()[p].g as f64; let tr = want.pixels()[p].g as f64; let tw = twin.pixels()[p].g as f64;
            total += tr * o;
            let cat = match maps.point_of_pixel(p) {
                None => "sky",
                Some(kk) => match maps.albedo()[kk] {
                    None => "no albedo",
                    Some(_) => {
                        let now = lt.sun_term(kk, sun) > 0.0;
                        let cap = maps.capture_sun_terms()[kk] > 0.0;
                        match (cap, now) { (true, true) => "lit cap, lit now", (true, false) => "lit cap, shade now", (false, true) => "shade cap, lit now", (false, false) => "shade cap, shade now" }
                    }
                }
            };
            let e = cats.entry(cat).or_default();
            e[0] += (g - tr) * o; e[1] += (g - tr).abs() * o; e[2] += (tw - tr).abs() * o; e[3] += tr * o;
        }
        for (c, v) in cats { println!("   {c:22} truth share {:5.1} %  signed {:+6.2} %  abs {:5.2} %  twin abs {:5.2} %  (of the total)", 100.0*v[3]/total, 100.0*v[0]/total, 100.0*v[1]/total, 100.0*v[2]/total); }
    }
}
