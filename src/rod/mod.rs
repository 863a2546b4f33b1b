//! Discrete elastic rods (`../shared/design/02-yarn-model.md`, "Discrete elastic rods"; Bergou et al. 2008,
//! 2010): frames, parallel transport, reference twist, and the stretching and bending+twisting stencils.

mod material;

pub use material::YarnMaterial;
