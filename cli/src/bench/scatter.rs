//! Placeholder: benchmark of the scatter unit, being written.

pub fn run(_n_items: usize) -> anyhow::Result<()> {
    Ok(())
}
