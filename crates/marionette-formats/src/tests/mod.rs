//! The readers' unit tests: valid inputs from memory, malformed ones with their messages.

mod bvh;
mod keypoints;
mod readers;
