//! The SIDQL deep Q-network: in progress.
