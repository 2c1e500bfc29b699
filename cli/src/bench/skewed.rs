//! Placeholder: benchmark of the skewed unit, being written.

pub fn run(_n_items: usize) -> anyhow::Result<()> {
    Ok(())
}
