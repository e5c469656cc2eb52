//! `cargo regen`: regenerates the register-map artefacts from `hdl-interface/regmap.toml`.
//!
//! `cargo regen --check` writes nothing and exits 1 when a committed output is stale.

use std::process::ExitCode;

use stereocal_hdl_regen::{
    generate, hdl_interface_dir, read_description, stale_outputs, RegenError,
};

fn main() -> ExitCode {
    let check = match std::env::args().nth(1).as_deref() {
        None => false,
        Some("--check") => true,
        Some(other) => {
            eprintln!("error: unknown argument `{other}` (usage: cargo regen [--check])");
            return ExitCode::from(2);
        }
    };
    match run(check) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run(check: bool) -> Result<ExitCode, RegenError> {
    let dir = hdl_interface_dir();
    let outputs = generate(&read_description(&dir)?)?;
    if check {
        let stale = stale_outputs(&dir, &outputs);
        if stale.is_empty() {
            println!("hdl-interface generated files are up to date");
            return Ok(ExitCode::SUCCESS);
        }
        for path in stale {
            eprintln!("stale: hdl-interface/{path}");
        }
        eprintln!(
            "hdl-interface generated files are not up to date: regenerate with `cargo regen`"
        );
        return Ok(ExitCode::FAILURE);
    }
    for output in &outputs {
        let path = dir.join(output.path);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).map_err(|source| RegenError::Io {
                path: parent.to_path_buf(),
                source,
            })?;
        }
        // Rewrite only what changed, so file times (and rebuilds) follow real changes.
        if std::fs::read_to_string(&path).is_ok_and(|old| old == output.contents) {
            continue;
        }
        std::fs::write(&path, &output.contents).map_err(|source| RegenError::Io {
            path: path.clone(),
            source,
        })?;
        println!("wrote hdl-interface/{}", output.path);
    }
    Ok(ExitCode::SUCCESS)
}
