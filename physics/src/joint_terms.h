// What a joint's Gauss-Seidel visits read of its bodies' poses: lever arms, the rows' directions,
// their effective masses factored, the free coordinate and the cone's lean. Between two moves the
// poses stay put (only a move and the position passes after it change them; a step's inverse
// inertias are fixed), yet a sweep recomputed all of it at every visit: the soft solver sweeps a
// joint six times between two moves, pgs ten times, and in a pile of ragdolls that was a third of
// the step (two arctangents, a rotation between two vectors and a 3 x 3 factoring a joint a
// visit). So an island works them out once after each move (prepare_joint_terms) and its visits
// read them. The arithmetic is the visits' own, in the same order: the same bits as before.
// Private to the engine.
#pragma once

#include <Eigen/Dense>
#include <span>

#include "block_solve.h"
#include "joint_geometry.h"

namespace tumble {

// A hinge's two angular rows: axis a stays perpendicular to two directions b2, c2 perpendicular
// to axis b (Jolt's HingeRotationConstraintPart has the same rows). d/dt (axis_a . d) =
// (w_b - w_a) . (d x axis_a) for d fixed in b, so the rows' directions are g = d x axis_a.
struct HingeRows {
  Vec3 axis_a, b2, c2, g1, g2;
  Eigen::Matrix2d k;  // effective inverse mass of the two rows
  Eigen::Vector2d error() const { return {axis_a.dot(b2), axis_a.dot(c2)}; }
};
HingeRows hinge_rows(const Joint& joint, const Quat& qa, const Quat* qb, const Mat3& inertia);

// A slider's two rows across its axis: b's anchor stays on the line through a's anchor along
// a's axis (the rows' lever arm on a reaches b's anchor, as the offset's does).
struct SliderRows {
  joint_detail::AxialRow rows[2];
  Eigen::Matrix2d k;
  Eigen::Vector2d error;
};
SliderRows slider_rows(const Joint& joint, const Pose& pose_a, const Pose& pose_b, bool world_b,
                       const SolverBody& a, const SolverBody& b);

struct JointPoseTerms {
  joint_detail::Anchors anchors;
  // The springs', motors', limits' and friction's row along the free coordinate (joint_axial.h)
  // and its effective inverse mass: worked out where the joint has one of them or an impulse
  // along it to warm-start (`exists` false otherwise).
  joint_detail::FreeCoordinate coordinate;
  double coordinate_mass = 0;
  // A ball's cone: its lean and that row's effective inverse mass (where it has a cone).
  joint_detail::Swing swing;
  double cone_mass = 0;
  // A ball's friction: what resists the relative turn (the moving bodies' inverse inertias).
  Mat3 mobility = Mat3::Zero();
  BlockSolve3 mobility_solver;
  bool mobility_usable = false;
  // The joint's own rows, where the sweeps solve them (not the direct solve, joint_tree.h):
  // the point's block (ball, hinge, fixed), inverted (block_solve.h);
  Mat3 point = Mat3::Zero();
  BlockSolve3 point_solver;
  // a hinge's axes;
  HingeRows hinge;
  BlockSolve2 hinge_solver;
  bool hinge_usable = false;
  // a fixed joint's or slider's rotation;
  Mat3 rotation = Mat3::Zero();
  BlockSolve3 rotation_solver;
  bool rotation_usable = false;
  // a slider's rows across its axis.
  SliderRows slider;
  BlockSolve2 slider_solver;
  bool slider_usable = false;
};

// The terms at the present poses. `own_rows`: the sweeps solve the joint's own rows too (else
// only its drives and bounds: the direct solve holds the rest).
void prepare_joint_terms(const JointRow& row, std::span<const SolverBody> bodies,
                         std::span<const Pose> poses, bool own_rows, JointPoseTerms* terms);

}  // namespace tumble
