//! Tests of `plyscape::integrate`: the order of convergence, events at
//! the segment changes of a law, and forward sensitivities in both forms.
mod convergence;
mod events;
mod sens;
