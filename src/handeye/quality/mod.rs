//! Quality: input mistakes caught before solving ([`checks`], [`gross`]
//! for one grossly wrong pose, [`pairing`] for robot and camera poses that
//! do not belong together), the measures of a solution ([`residuals`]:
//! closure residuals and summary errors; [`repeat`]: leave-one-out and
//! bootstrap), and whether its reported uncertainty can be trusted
//! ([`trust`], [`intrinsics_move`] for a joint refinement that moved the
//! intrinsics too far, [`focal`] for a focal length that the robot's motion
//! disagrees with), and what the error is where the robot works
//! ([`work_point`], [`verify`] against held-out poses and touched points).

pub mod checks;
pub mod focal;
pub mod gross;
pub mod intrinsics_move;
pub mod pairing;
pub mod repeat;
pub mod residuals;
pub mod trust;
pub mod verify;
pub mod work_point;
