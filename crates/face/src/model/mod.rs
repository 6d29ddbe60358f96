//! The networks of §3.2: the input layout shared by training and inference, the BiLSTM generator and
//! the convolutional critic.

pub mod critic;
pub mod generator;
pub mod input;
pub mod runtime;
