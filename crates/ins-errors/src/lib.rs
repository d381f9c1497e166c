//! Strapdown INS error analysis (work in progress; see module docs).

pub mod earth;
