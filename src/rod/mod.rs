//! Discrete elastic rods (`docs/yarn-model.md`, "Discrete elastic rods"; Bergou et al. 2008,
//! 2010): frames, parallel transport, reference twist, and the stretching and bending+twisting stencils.

pub mod bend_twist;
pub mod checked;
pub mod frame;
pub mod generic;
pub mod jet;
mod material;
pub mod state;
pub mod stretch;

pub use bend_twist::{BendTwistParams, StencilFrames};
pub use frame::BendingForm;
pub use material::{YarnFileError, YarnMaterial, MAX_CONTACT_QUADRATURE};
pub use state::{raw_reference_twists, set_rest_to_current, RodState, RodTopology, StencilDofs};
