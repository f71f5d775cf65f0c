//! The scene as the editor holds it: characters' identity and index, capture into a
//! document, spawning from documents ([`document`]), re-placing characters once
//! skinned ([`arrange`]) props held by joints ([`attach`]) and clips retargeted from other humanoids ([`retarget`]). Files and layout themselves are the document layer's.

pub mod arrange;
pub mod attach;
pub mod document;
pub mod retarget;
