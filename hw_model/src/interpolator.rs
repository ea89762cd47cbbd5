//! placeholder: implemented by the hw_model work.
