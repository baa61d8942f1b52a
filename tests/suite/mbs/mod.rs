//! Tests of `plyscape::mbs` on the scenes built on it: the kernel's
//! identities, joints, loads, flexible bodies, energy, mechanisms and the
//! SAR scenes.
mod andrews;
mod energy;
mod flex;
mod free;
mod joint_prestress;
mod kernel;
mod loads;
mod mechanisms;
mod prismatic;
mod sar;
mod sar_clamp;
mod sar_flex;
mod sar_fold;
mod sar_holddown;
mod slider_crank;
mod stiffening;
mod thickness;
mod torsion;
