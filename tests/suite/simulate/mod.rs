//! Tests of `plyscape::simulate`: responses and their gradients over a
//! run's outputs, natural frequencies as responses, and runs that hold or
//! stop cleanly.
mod deploy_hinge;
mod flexible_responses;
mod responses;
mod responses_flex;
mod robust;
