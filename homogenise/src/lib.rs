//! homogenise
