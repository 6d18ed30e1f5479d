//! The viewer's sequence mode on the bundled courtyard (`assets/outdoor/courtyard`, Jensen,
//! Andersen & Madsen 2006): the estimates it plays are `ibl outdoor`'s, bit for bit (one library
//! loop, `ibl_pipeline::outdoor_sequence`), and its frames match the CPU composite of the same
//! frame and estimate.
//!
//! Truth and its noise: the CPU composite (`ibl_outdoor::FrameCompositor`, 64 Sobol samples per
//! pixel, 8 occlusion rays each) differs from the viewer by construction where the viewer
//! leaves things out (`sequence_player`'s notes): the objects' occlusion of the sky ambient (their
//! sky shadow on the ground and on themselves) and shadow maps instead of shadow rays. The
//! threshold is the GPU-against-CPU bound (mean FLIP <= 0.05) on the whole frame.

mod common;

use ibl_outdoor::{CompositeSettings, FrameCompositor};
use ibl_pipeline::outdoor::{OutdoorJob, run_outdoor};
use ibl_pipeline::outdoor_sequence::OutdoorSequence;
use ibl_pipeline::progress::Silent;
use ibl_viewer::headless::{self, HeadlessOptions};
use ibl_viewer::sequence_player::SequencePlayer;
use ibl_viewer::{SceneModel, ViewJob};

fn courtyard() -> std::path::PathBuf {
    common::assets().join("outdoor/courtyard/scene.toml")
}

#[test]
fn the_sequence_plays_the_estimates_of_ibl_outdoor() {
    let Some(_gpu) = common::gpu_or_skip("sequence estimates") else {
        return;
    };
    let job = ViewJob {
        input: courtyard(),
        mapping: None,
        output: None,
        frames: HeadlessOptions {
            size: (160, 120),
            frames: 8,
            ..Default::default()
        },
        exposure_stops: None,
        curve: ibl_core::tonemap::ToneCurve::Reinhard,
        method: None,
        lights: None,
        bands: None,
        probe: ibl_viewer::view_job::ProbeViewOptions {
            projection: ibl_viewer::probe_pass::ProbeProjection::LookAround,
            layer: ibl_viewer::probe_pass::ProbeLayer::Radiance,
            sharpen: 0.0,
            overlays: ibl_viewer::probe_model::Overlays {
                lights: false,
                regions: false,
                dominant: false,
            },
        },
    };
    let viewed = job.run(&Silent).expect("the viewer plays the sequence");
    assert_eq!(viewed.kind, ibl_viewer::view_job::ViewKind::Sequence);
    let played = viewed.sequence.expect("a sequence summary").frames;
    assert_eq!(played.len(), 8);

    let out = tempfile::tempdir().expect("a temporary folder");
    let mut outdoor = OutdoorJob::new(courtyard(), out.path().join("run"));
    outdoor.composites = false;
    let summary = run_outdoor(&outdoor, &Silent).expect("ibl outdoor runs");
    assert_eq!(summary.frames.len(), 8);
    for (v, o) in played.iter().zip(&summary.frames) {
        assert_eq!(
            (v.index, &v.name, &v.local_time),
            (o.index, &o.name, &o.local_time)
        );
        assert_eq!(v.result.estimate.sun, o.result.estimate.sun, "{}", v.name);
        assert_eq!(v.result.estimate.sky, o.result.estimate.sky, "{}", v.name);
        assert_eq!(v.result.sun_direction, o.result.sun_direction, "{}", v.name);
    }
}

/// The viewer's frame `index` of the courtyard (its sky as `sky_lights` shadowed lights, or the
/// ambient for 0) against the CPU composite of the same frame.
fn compare_frame(index: usize, label: &str, sky_lights: usize) {
    let Some(gpu) = common::gpu_or_skip(label) else {
        return;
    };
    let path = courtyard();
    let model = SceneModel::open(&path).expect("the courtyard opens");
    let mut sequence = OutdoorSequence::open(&path, None).expect("the sequence opens");
    let mut system = sequence.system().expect("the offline step");
    let mut frame = None;
    for _ in 0..=index {
        let next = sequence.next_frame().expect("reads").expect("a frame");
        let image = next.image.expect("daylight");
        let result = system.process(next.time, &image).expect("estimates");
        frame = Some((image, result));
    }
    let (image, result) = frame.expect("the frame");
    let (w, h) = (image.width() as u32, image.height() as u32);
    let scene = &sequence.loaded.scene;
    let compositor = FrameCompositor::new(
        scene.real.clone(),
        scene.virtual_objects.clone(),
        scene.camera,
        scene.probe.position,
        scene.probe.world_from_probe,
        CompositeSettings {
            spp: 64,
            ..CompositeSettings::default()
        },
    )
    .expect("the compositor");
    let lighting = system
        .frame_lighting(&result)
        .expect("the frame's lighting");
    let cpu = compositor
        .composite(&image, &lighting)
        .expect("the CPU composite");

    let centre = model.objects_sphere().map(|(c, _)| c);
    let mut player = SequencePlayer::open(&path, centre, &[]).expect("the player");
    let options = HeadlessOptions {
        size: (w, h),
        frames: index as u32 + 1,
        sky_lights,
        ..Default::default()
    };
    let run = headless::render_sequence(&gpu, &model, &mut player, &options, &|_, _| {})
        .expect("the viewer renders");
    assert_eq!(run.played.last().map(|f| f.index), Some(index));

    let (outcome, masks_equal) =
        common::against_cpu(&format!("viewer-sequence-{label}"), &run.images, &cpu, 0.05);
    eprintln!(
        "courtyard frame {index} ({label}, {sky_lights} sky lights): {outcome:?}, coverage masks equal on {:.3} %",
        100.0 * masks_equal
    );
    if let Err(e) = outcome {
        panic!("{label}: {e}");
    }
    assert!(
        masks_equal >= 0.995,
        "{label}: masks equal on {masks_equal}"
    );
}

#[test]
fn a_clear_frame_matches_the_cpu_composite() {
    // 10:00, clear: the objects sunlit, their sun shadow on the paving.
    compare_frame(0, "clear", 0);
}

#[test]
fn an_overcast_frame_matches_the_cpu_composite() {
    // 14:00, overcast: no sun shadow, only the sky's.
    compare_frame(4, "overcast", 0);
}

#[test]
fn an_overcast_frame_with_the_sky_as_shadowed_lights_matches_the_cpu_composite() {
    // 14:00, overcast, the sky as 8 median-cut lights with their shadows: the statue's sky
    // shadow, which the unshadowed ambient leaves out.
    compare_frame(4, "overcast-sky-lights", 8);
}

#[test]
fn a_scene_without_an_outdoor_table_is_not_a_sequence() {
    let path = common::assets().join("scenes/bunny-sky.toml");
    let err = SequencePlayer::open(&path, None, &[])
        .err()
        .expect("bunny-sky has no [outdoor] table");
    assert!(err.is_bad_input());
    assert!(err.to_string().contains("[outdoor]"), "{err}");
}

#[test]
fn an_output_over_a_frame_is_refused() {
    let frame = common::assets().join("outdoor/courtyard/frames/1200.exr");
    let err = SequencePlayer::open(&courtyard(), None, &[frame.as_path()])
        .err()
        .expect("writing over a frame is refused");
    assert!(err.is_bad_input());
    assert!(err.to_string().contains("1200.exr"), "{err}");
}
