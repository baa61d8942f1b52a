//! Tests of `plyscape::laminate`: ABD stiffness and its derivatives.
mod abd;
