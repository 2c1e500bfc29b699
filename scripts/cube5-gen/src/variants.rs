//! The one reader of `rtl/**/<top>.variants` and `<top>.f` filelists (being written).

/// `cube5-gen variants ...`.
pub fn main(_args: &[String]) -> Result<(), String> {
    Err("variants: not written yet".into())
}
