//! Arbitrary text into the calibration readers (`Calibration::from_str_any`, what
//! `Calibration::load` and the CLI's `--calib` use: TOML, OpenCV YAML, Kalibr, KITTI). Nothing
//! may panic; a calibration that parses must be valid and must survive `to_toml_string` →
//! `from_toml_str` unchanged, whichever format it came in.
//! Bytes that are not UTF-8 go in lossily converted, so every input reaches the parser.
#![no_main]

use libfuzzer_sys::fuzz_target;
use stereocal::calib::Calibration;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    if let Ok(calib) = Calibration::from_str_any(&text, "fuzz.toml") {
        calib
            .validate("fuzz.toml".as_ref())
            .expect("a parsed calibration is valid");
        let again = Calibration::from_toml_str(&calib.to_toml_string(), "again.toml")
            .expect("a serialised calibration parses");
        assert_eq!(again, calib);
    }
});
