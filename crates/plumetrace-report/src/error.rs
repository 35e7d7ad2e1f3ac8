//! What can go wrong drawing a figure or writing a page.

/// A report error. Drawing errors carry plotters' error as text (debug-formatted).
#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    /// The mission figure (or a map panel) could not be drawn.
    #[error("drawing the figure: {0}")]
    Figure(String),
    /// The team figure could not be drawn.
    #[error("drawing the team figure: {0}")]
    TeamFigure(String),
    /// The plume figure could not be drawn.
    #[error("drawing: {0}")]
    PlumeFigure(String),
    /// The replay page's data has a number that is not finite (at this path in the data).
    #[error("the replay page's data has a number that is not finite ({0})")]
    NonFinite(String),
    /// The replay page's data could not be encoded.
    #[error("encoding the page: {0}")]
    Encode(serde_json::Error),
}

impl ReportError {
    /// A drawing error of the mission figure (or a map panel).
    pub(crate) fn figure<E: std::fmt::Debug>(e: E) -> Self {
        ReportError::Figure(format!("{e:?}"))
    }
}
