//! Placeholder: benchmark of the compos unit, being written.

pub fn run(_n_items: usize) -> anyhow::Result<()> {
    Ok(())
}
