//! Composite panels as parts of a mechanism: a panel's modal analysis
//! across lay-ups ([`analysis`]) and its modes as the
//! [`crate::mbs::ModalBasis`] of a floating-frame flexible body
//! ([`basis`]), one computation for the bodies whose bases have the
//! same content ([`shared`]). The `plyscape modes` study section that
//! tabulates them is [`crate::sections::modes`].

pub mod analysis;
pub mod basis;
mod geometric;
pub mod rigid;
pub mod shared;

pub use analysis::{
    analyse_panel, dfreq_hz_per_deg, group_name, in_panel, layup_label, PanelAnalysis, PanelModes,
    FREE_FREE_SHIFT,
};
pub use basis::{
    basis_for_study, basis_for_study_thickness, panel_basis, panel_basis_geometric,
    thickness_group, unknown_panel, BasisBuilder,
};
pub use rigid::RigidFrame;
