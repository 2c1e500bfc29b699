//! Errors of the golden model: everything a user can get wrong is a value, never a panic.

use thiserror::Error;

#[derive(Debug, Error)]
pub enum ModelError {
    #[error("configuration: {0}")]
    Config(String),
    #[error("{path}: {message}")]
    Scene { path: String, message: String },
    #[error("volume: {0}")]
    Volume(String),
    #[error("view: {0}")]
    View(String),
    #[error("image: {0}")]
    Image(String),
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
}

pub type Result<T> = std::result::Result<T, ModelError>;
