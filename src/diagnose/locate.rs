//! locate — placeholder
