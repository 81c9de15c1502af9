//! plot — placeholder
