//! Bad configuration and bad feeding give typed errors; a FIFO the driver does not drain
//! counts what it drops.

use stereocal_firmware::fabric::{
    Config, ConfigError, FastFrontEnd, FrameError, FrontEnd, RegisterFrontEnd,
};

fn check_errors<F: FrontEnd>(fe: &mut F) {
    assert_eq!(fe.push_row(&[0; 32]), Err(FrameError::NotStarted));
    let mut c = Config::new(32, 24);
    c.octaves = 0;
    assert_eq!(fe.start_frame(&c), Err(ConfigError::Octaves(0)));
    c.octaves = 5;
    assert_eq!(fe.start_frame(&c), Err(ConfigError::Octaves(5)));
    let c = Config::new(16, 16); // octave 3 would be 2x2
    assert!(matches!(
        fe.start_frame(&c),
        Err(ConfigError::TooSmall { .. })
    ));
    let mut c = Config::new(200, 24);
    c.octaves = 1;
    assert!(matches!(
        fe.start_frame(&c),
        Err(ConfigError::TooWide { width: 200, .. })
    ));
    let mut c = Config::new(32, 24);
    c.octaves = 2;
    c.sobel_scale = 4;
    assert_eq!(fe.start_frame(&c), Err(ConfigError::SobelScale(4)));
    c.sobel_scale = 1;
    c.max_offset = 8192;
    assert_eq!(fe.start_frame(&c), Err(ConfigError::MaxOffset(8192)));
    c.max_offset = 4096;
    fe.start_frame(&c).unwrap();
    assert_eq!(
        fe.push_row(&[0; 31]),
        Err(FrameError::RowLength {
            expected: 32,
            got: 31
        })
    );
    for _ in 0..24 {
        fe.push_row(&[7; 32]).unwrap();
    }
    assert_eq!(fe.push_row(&[7; 32]), Err(FrameError::TooManyRows));
    // Never drained: 32·24 + 16·12 Sobel pixels into a 3·128-entry FIFO.
    while !fe.blank_row() {}
    let o = fe.overflow();
    assert_eq!(
        o.sobel as usize,
        32 * 24 + 16 * 12 - 3 * 128,
        "every dropped pixel is counted"
    );
}

#[test]
fn register_model_errors() {
    check_errors(&mut RegisterFrontEnd::<128, 64, 32, 16>::new());
}

#[test]
fn fast_path_errors() {
    check_errors(&mut FastFrontEnd::<128, 64, 32, 16>::new());
}
