use ibl_outdoor::courtyard::Courtyard;
use ibl_outdoor::synthetic::SyntheticDay;
use ibl_outdoor::tracking::SkyTracker;
use ibl_outdoor::*;
use ibl_core::{LatLong, Rgb, Image};
use glam::Vec3;
use ibl_io::{WriteOptions, write_image};
fn map_error(got: &Image<Rgb>, want: &Image<Rgb>, sun: Vec3) -> f64 {
    let (w, h) = (want.width(), want.height());
    let grid = LatLong::new(w, h);
    let omega = grid.row_solid_angles();
    let block = 4;
    let mut err = [0.0f64; 3];
    let mut sum = [0.0f64; 3];
    for bj in 0..h / block {
        for bi in 0..w / block {
            let mut g = [0.0f64; 3];
            let mut t = [0.0f64; 3];
            let mut area = 0.0;
            let mut near_sun = false;
            for j in bj * block..(bj + 1) * block {
                for i in bi * block..(bi + 1) * block {
                    if grid.pixel_dir(i, j).dot(sun) > 3f32.to_radians().cos() {
                        near_sun = true;
                    }
                    let (a, b) = (got.get(i, j).to_array(), want.get(i, j).to_array());
                    for c in 0..3 {
                        g[c] += f64::from(a[c]) * omega[j];
                        t[c] += f64::from(b[c]) * omega[j];
                    }
                    area += omega[j];
                }
            }
            if near_sun || area == 0.0 {
                continue;
            }
            for c in 0..3 {
                err[c] += (g[c] - t[c]).abs();
                sum[c] += t[c];
            }
        }
    }
    100.0 * (0..3).map(|c| err[c] / sum[c]).sum::<f64>() / 3.0
}


fn main() {
    let day = SyntheticDay::standard();
    let yard = Courtyard::new(day.frame_size);
    let t0 = day.frame_truth(0).unwrap();
    let probe = day.render_probe(&yard, &t0, 1).unwrap();
    let sun0 = Vec3::from_array(t0.parameters.sun_direction);
    let maps = ProbeMaps::build(&yard.layer, &probe, yard.probe_position, glam::Mat3::IDENTITY, sun0, CaptureSource::Measured, MapSettings::default()).unwrap();
    let k = 5;
    let t = day.frame_truth(k).unwrap();
    let sun = Vec3::from_array(t.parameters.sun_direction);
    let truth = day.render_probe(&yard, &t, 77).unwrap();
    let mut sky = SkyTracker::new(SkyModel::Preetham{turbidity:3.0}, 8, 0.017);
    sky.update(sun).unwrap();
    let mut r = Relighter::new(0.004);
    r.update(&yard.layer, &maps, &sky, sun).unwrap();
    let relit = r.relight(&maps, sun, Rgb::from_array(t.parameters.sky), Rgb::from_array(t.parameters.sun)).unwrap();
    let (w,h) = maps.size();
    let grid = LatLong::new(w,h); let om = grid.row_solid_angles();
    // classes: 0 sky, 1 surface with albedo, 2 no albedo
    let mut err=[0.0f64;3]; let mut sum=0.0f64; let mut cnt=[0usize;3];
    let mut eimg = Image::filled(w,h,Rgb::ZERO);
    for j in 0..h { for i in 0..w {
        let p = j*w+i;
        let cls = match maps.point_of_pixel(p) { None=>0, Some(q)=> if maps.albedo()[q].is_some() {1} else {2} };
        let a = relit.get(i,j).g as f64; let b = truth.get(i,j).g as f64;
        if grid.pixel_dir(i,j).dot(sun) > 3f32.to_radians().cos() { continue; }
        err[cls] += (a-b).abs()*om[j]; sum += b*om[j]; cnt[cls]+=1;
        *eimg.get_mut(i,j) = Rgb::splat(((a-b).abs()/b.max(1e-3)) as f32);
    }}
    println!("per-pixel error share (green, % of total): sky {:.2} surf {:.2} noalb {:.2}; counts {:?}", 100.0*err[0]/sum, 100.0*err[1]/sum, 100.0*err[2]/sum, cnt);
    let twin = day.render_probe(&yard, &t, 78).unwrap();
    println!("block error relit(truth params) {:.2} %, twin floor {:.2} %", map_error(&relit, &truth, sun), map_error(&twin, &truth, sun));
    for spp in [256u32] {
        let d2 = SyntheticDay { probe_spp: spp, ..SyntheticDay::standard() };
        let probe = d2.render_probe(&yard, &t0, 1).unwrap();
        let maps = ProbeMaps::build(&yard.layer, &probe, yard.probe_position, glam::Mat3::IDENTITY, sun0, CaptureSource::Measured, MapSettings::default()).unwrap();
        let mut r = Relighter::new(0.004);
        r.update(&yard.layer, &maps, &sky, sun).unwrap();
        let relit = r.relight(&maps, sun, Rgb::from_array(t.parameters.sky), Rgb::from_array(t.parameters.sun)).unwrap();
        let truth = d2.render_probe(&yard, &t, 77).unwrap();
        println!("capture spp {spp}: block error relit(truth params) {:.2} %", map_error(&relit, &truth, sun));
    }
    write_image(std::path::Path::new("/tmp/od/relerr.png"), &eimg, &WriteOptions::default()).unwrap();
    write_image(std::path::Path::new("/tmp/od/relit.png"), &relit, &WriteOptions::default()).unwrap();
    write_image(std::path::Path::new("/tmp/od/truth.png"), &truth, &WriteOptions::default()).unwrap();
}
