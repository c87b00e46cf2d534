//! A pattern too large for the assembly's slot map (reported by [`crate::assembly`]).

/// The pattern has more entries than the 32-bit slot map can address.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("the stiffness pattern has {0} entries, more than the 32-bit slot map holds")]
pub struct PatternTooLargeError(pub usize);
