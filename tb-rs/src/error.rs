//! The one error type of the test bench, for streams and frames alike: a run either could not
//! start (`Setup`), broke the valid/ready rules (`Protocol`), stopped producing (`Deadlock`), or
//! produced a different value from the golden model (`Mismatch`, with everything needed to
//! reproduce it).

use std::fmt;
use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum TbError {
    /// The run could not start: the variant is not built, its ports disagree with the model's
    /// codec, the top has no configuration port, or the model refused the configuration.
    #[error("{variant}: {what}")]
    Setup { variant: String, what: String },
    /// The RTL broke the stream protocol (a stalled output dropped valid or changed its data) or
    /// stopped the simulation (`$finish`, a failed assertion).
    #[error("{variant}: protocol: {what} (cycle {cycle}; reproduce with CUBE5_SEED={seed})")]
    Protocol {
        variant: String,
        seed: u64,
        cycle: u64,
        what: String,
    },
    /// The RTL stopped producing before every expected output was taken.
    #[error("{variant}: deadlock: {what} (cycle {cycle}; reproduce with CUBE5_SEED={seed})")]
    Deadlock {
        variant: String,
        seed: u64,
        cycle: u64,
        what: String,
    },
    /// The first output that differs from the model's.
    #[error("{0}")]
    Mismatch(Box<Mismatch>),
}

impl TbError {
    pub fn setup(variant: &str, what: impl fmt::Display) -> Self {
        TbError::Setup {
            variant: variant.to_string(),
            what: what.to_string(),
        }
    }

    /// The mismatch, if this is one.
    pub fn mismatch(&self) -> Option<&Mismatch> {
        match self {
            TbError::Mismatch(m) => Some(m),
            _ => None,
        }
    }
}

/// The model refused a set-up (a table, a view, a configuration).
impl From<cube5_model::ModelError> for TbError {
    fn from(e: cube5_model::ModelError) -> Self {
        TbError::setup("model", e)
    }
}

impl From<Mismatch> for TbError {
    fn from(m: Mismatch) -> Self {
        TbError::Mismatch(Box::new(m))
    }
}

/// The first difference between RTL and model, with everything needed to reproduce it.
#[derive(Debug, Clone, Default)]
pub struct Mismatch {
    pub variant: String,
    pub seed: u64,
    /// The item (stream) or output index (frame: pixel `q * W + r`) that differs.
    pub item: u64,
    /// The cycle the output was taken.
    pub cycle: u64,
    /// What went in (stream: the input item; frame: the view and the pixel).
    pub input: String,
    pub rtl: String,
    pub model: String,
    pub rtl_words: Vec<u32>,
    pub waveform: Option<PathBuf>,
    /// What differs.
    pub what: String,
    /// The model's account of the item, where one helps (frame: the samples of the ray).
    pub trail: String,
}

impl fmt::Display for Mismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "MISMATCH in {} ({}), seed {}",
            self.variant, self.what, self.seed
        )?;
        writeln!(
            f,
            "  item   #{} (output taken at cycle {})",
            self.item, self.cycle
        )?;
        writeln!(f, "  input  {}", self.input)?;
        if self.rtl_words.is_empty() {
            writeln!(f, "  rtl    {}", self.rtl)?;
        } else {
            writeln!(f, "  rtl    {}  (words {:08x?})", self.rtl, self.rtl_words)?;
        }
        writeln!(f, "  model  {}", self.model)?;
        if !self.trail.is_empty() {
            writeln!(f, "  {}", self.trail)?;
        }
        match &self.waveform {
            Some(p) => writeln!(f, "  waveform {}", p.display())?,
            None => writeln!(
                f,
                "  waveform: not written (unset CUBE5_NO_WAVES to get one)"
            )?,
        }
        write!(f, "  reproduce with CUBE5_SEED={}", self.seed)
    }
}
