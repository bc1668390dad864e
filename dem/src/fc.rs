//! Standalone frictional-contact problems (fc-problem-v1).
