//! rig — placeholder; see the issue that owns it.
