pub fn run(_a: &crate::args::ServeArgs) -> anyhow::Result<bool> {
    anyhow::bail!("not yet")
}
