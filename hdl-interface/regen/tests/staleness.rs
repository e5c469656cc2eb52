//! The committed outputs must be exactly what `cargo regen` would write now.

use stereocal_hdl_regen::{generate, hdl_interface_dir, read_description, stale_outputs};

#[test]
fn generated_files_are_up_to_date() {
    let dir = hdl_interface_dir();
    let source = read_description(&dir).unwrap_or_else(|e| panic!("{e}"));
    let outputs = generate(&source).unwrap_or_else(|e| panic!("{e}"));
    let stale = stale_outputs(&dir, &outputs);
    assert!(
        stale.is_empty(),
        "hdl-interface generated files are not up to date: regenerate with `cargo regen` \
         (stale: {})",
        stale.join(", ")
    );
}

#[test]
fn every_output_carries_the_banner() {
    let source = read_description(&hdl_interface_dir()).unwrap_or_else(|e| panic!("{e}"));
    for output in generate(&source).unwrap_or_else(|e| panic!("{e}")) {
        let first_line = output.contents.lines().next().unwrap_or_default();
        assert!(
            first_line.contains(stereocal_hdl_regen::BANNER),
            "{}: first line `{first_line}` lacks the banner",
            output.path
        );
    }
}

#[test]
fn every_committed_output_is_checked() {
    use stereocal_hdl_regen::{
        C_PATH, MARKDOWN_PATH, RUST_API_PATH, RUST_PATH, VERILOG_PATH, VERILOG_REGS_PATH,
    };
    let source = read_description(&hdl_interface_dir()).unwrap_or_else(|e| panic!("{e}"));
    let outputs = generate(&source).unwrap_or_else(|e| panic!("{e}"));
    let paths: Vec<&str> = outputs.iter().map(|o| o.path).collect();
    assert_eq!(
        paths,
        [
            RUST_PATH,
            RUST_API_PATH,
            C_PATH,
            VERILOG_PATH,
            MARKDOWN_PATH,
            VERILOG_REGS_PATH
        ],
        "the staleness check covers exactly these files"
    );
}
