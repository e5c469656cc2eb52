//! Arbitrary bytes into the image reader (`sequence::decode_gray`, which `load_gray` calls on
//! a file's contents), under each extension the sequence reader lists and none. Nothing may
//! panic; an image that decodes must hold exactly width × height grey pixels.
//!
//! The `image` crate's default limits (512 MiB per allocation) stay on, as in `load_gray`.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;
use stereocal::image_sequence::decode_gray;

const NAMES: [&str; 5] = ["fuzz.png", "fuzz.pgm", "fuzz.jpg", "fuzz.jpeg", "fuzz"];

fuzz_target!(|data: &[u8]| {
    // The last byte picks the name, so the content's leading magic stays free to mutate.
    let name = NAMES[data.last().map_or(0, |&b| usize::from(b) % NAMES.len())];
    if let Ok(frame) = decode_gray(data, Path::new(name)) {
        assert_eq!(frame.pixels.len(), frame.width * frame.height);
    }
});
