//! The `stereocal` command line.
fn main() -> anyhow::Result<()> {
    anyhow::bail!("stereocal: command line not wired yet")
}
