//! The scene as the editor holds it: characters' identity and index, capture into a
//! document, spawning from documents ([`document`]), and re-placing characters once
//! skinned ([`arrange`]). Files and layout themselves are the document layer's.

pub mod arrange;
pub mod document;
