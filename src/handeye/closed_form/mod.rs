//! The closed-form solvers: AX = XB over motion pairs ([`axxb`]:
//! Tsai-Lenz, Park-Martin, Horaud, Chou-Kamel, Andreff; [`daniilidis`]:
//! dual quaternions), AX = ZB over the views ([`axzb`]: Shah, Li), the
//! observable part when every motion rotates about one axis ([`scara`]),
//! and the motions they take ([`motion`]).

pub mod axxb;
pub mod axzb;
pub mod daniilidis;
pub mod motion;
pub mod scara;
