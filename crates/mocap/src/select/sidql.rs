//! SIDQL selection (§4): placeholder until the DQN lands.
