//! Fuzz target: a batch spec's text (`ibl-pipeline::batch_spec`, read by `ibl batch` and
//! `python -m iblkit.batch`) must parse to a checked spec or an error naming the file, for any
//! bytes, never panic; a parsed spec's steps hash the same twice.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else { return };
    let path = Path::new("fuzz/spec.toml");
    match ibl_pipeline::batch_spec::BatchSpec::parse(text, path) {
        Ok(spec) => assert_eq!(spec.steps_sha256(), spec.steps_sha256()),
        Err(e) => assert!(e.to_string().contains("spec.toml"), "{e}"),
    }
});
