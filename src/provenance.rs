//! Where a result came from: written into every JSON file texsim produces.

use serde::Serialize;

/// The texsim version, the git commit it was built from (when built from a checkout: its HEAD
/// at build time; uncommitted changes are not recorded), the command line and the vector
/// instruction set the batch kernels ran with (it changes times, never results).
#[derive(Clone, Debug, Serialize, PartialEq, Eq)]
pub struct Provenance {
    pub texsim_version: &'static str,
    pub git_commit: Option<&'static str>,
    pub command_line: Vec<String>,
    pub vector_isa: &'static str,
}

impl Provenance {
    /// The provenance of this process, with `command_line` as given (the CLI passes its own
    /// arguments).
    #[must_use]
    pub fn new(command_line: Vec<String>) -> Self {
        Self {
            texsim_version: env!("CARGO_PKG_VERSION"),
            git_commit: option_env!("TEXSIM_GIT_COMMIT"),
            command_line,
            vector_isa: hw_model::vector_isa().name(),
        }
    }

    /// The provenance of this process with its own command line (`std::env::args`).
    #[must_use]
    pub fn of_process() -> Self {
        Self::new(std::env::args().collect())
    }
}
