//! `kapitza boundary`: placeholder until the stability API lands.

/// Stability window in m = A/ℓ from every criterion.
#[derive(Debug, Clone, clap::Args)]
pub struct Args {}

pub fn run(_args: &Args, _out: &mut dyn std::io::Write) -> anyhow::Result<()> {
    anyhow::bail!("not yet")
}
