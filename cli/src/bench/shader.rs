//! Placeholder: benchmark of the shader unit, being written.

pub fn run(_n_items: usize) -> anyhow::Result<()> {
    Ok(())
}
