//! The panel's modal basis for a floating-frame flexible body
//! (`plyscape::panels::basis`): lumped inertia against closed forms
//! ([`inertia`]), M-orthonormality, agreement with the modal solver, the
//! supports and the screening of nearly rigid modes ([`modes`]), design
//! derivatives and the invariants' derivatives against central finite
//! differences ([`derivatives`]), and input errors ([`input`]); the panels
//! they share are in [`fixtures`].
mod derivatives;
mod fixtures;
mod inertia;
mod input;
mod modes;

pub(super) use fixtures::laminate;
