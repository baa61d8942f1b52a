//! Floating-frame flexible bodies (paper Eqs. 5–6): conservation laws of a
//! free flexible body ([`free`]), exact Jacobian-vector products and
//! sensitivity lanes ([`kernel`]), the slow spin-up of a cantilever against
//! its quasi-static deflection and the effects switches ([`spin_up`]),
//! ply-angle sensitivities through a panel's modal basis against central
//! finite differences ([`sensitivities`]), and input errors ([`input`]);
//! the scenes they share are in [`scenes`].
mod free;
mod input;
mod kernel;
mod scenes;
mod sensitivities;
mod spin_up;
