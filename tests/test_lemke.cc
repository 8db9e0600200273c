// Lemke's algorithm on problems with known answers, and the exact solver against projected
// Gauss-Seidel on small stacks.
#include <gtest/gtest.h>

#include "lemke.h"
#include "scene_runner.h"
#include "test_support.h"

namespace tumble::testing {
namespace {

// w = M z + q >= 0, z >= 0, z.w = 0, to a tolerance relative to the data.
void expect_solution(const Eigen::MatrixXd& m, const Eigen::VectorXd& q, const Eigen::VectorXd& z) {
  const Eigen::VectorXd w = m * z + q;
  const double scale = 1e-9 * (1 + q.cwiseAbs().maxCoeff()) * (1 + m.cwiseAbs().maxCoeff());
  EXPECT_GE(z.minCoeff(), 0);
  EXPECT_GE(w.minCoeff(), -scale);
  for (int i = 0; i < z.size(); ++i)
    EXPECT_LE(std::abs(z[i] * w[i]), scale * (1 + z.cwiseAbs().maxCoeff()));
}

TEST(Lemke, SolvesPositiveDefiniteProblemsExactly) {
  Random random(7);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = random.integer(1, 30);
    Eigen::MatrixXd a(n, n);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        a(i, j) = random.uniform(-1, 1);
    const Eigen::MatrixXd m = a * a.transpose() + 0.1 * Eigen::MatrixXd::Identity(n, n);
    Eigen::VectorXd q(n);
    for (int i = 0; i < n; ++i)
      q[i] = random.uniform(-1, 1);
    Eigen::VectorXd z;
    const LemkeResult result = solve_lcp_lemke(m, q, 100 * n, &z);
    ASSERT_EQ(result.outcome, LemkeOutcome::kSolved) << "trial " << trial;
    expect_solution(m, q, z);
  }
}

// Singular positive semidefinite M with a feasible q (as four points on one face give): solvable,
// and the lexicographic rule must get through the degenerate pivots.
TEST(Lemke, SolvesDegenerateSemidefiniteProblems) {
  Random random(11);
  for (int trial = 0; trial < 300; ++trial) {
    const int n = random.integer(2, 30);
    const int rank = std::max(1, n / 3);
    Eigen::MatrixXd b(n, rank);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < rank; ++j)
        b(i, j) = random.uniform(-1, 1);
    const Eigen::MatrixXd m = b * b.transpose();
    Eigen::VectorXd x(n), y(n);
    for (int i = 0; i < n; ++i) {
      x[i] = random.uniform() < 0.5 ? 0.0 : random.uniform();
      y[i] = random.uniform() < 0.5 ? 0.0 : random.uniform();  // ties everywhere
    }
    const Eigen::VectorXd q = y - m * x;
    Eigen::VectorXd z;
    const LemkeResult result = solve_lcp_lemke(m, q, 100 * n, &z);
    ASSERT_EQ(result.outcome, LemkeOutcome::kSolved) << "trial " << trial;
    expect_solution(m, q, z);
  }
}

TEST(Lemke, ReportsInfeasibleProblemsAndBadInput) {
  // w = -z - 1 can never be >= 0: ray termination, not a wrong answer.
  Eigen::MatrixXd m = -Eigen::MatrixXd::Identity(2, 2);
  Eigen::VectorXd q = Eigen::VectorXd::Constant(2, -1);
  Eigen::VectorXd z;
  EXPECT_EQ(solve_lcp_lemke(m, q, 100, &z).outcome, LemkeOutcome::kRayTermination);
  q[0] = std::nan("");
  EXPECT_EQ(solve_lcp_lemke(Eigen::MatrixXd::Identity(2, 2), q, 100, &z).outcome,
            LemkeOutcome::kNotFinite);
  // The pivot bound is honoured and reported.
  Random random(3);
  Eigen::MatrixXd a = Eigen::MatrixXd::Random(20, 20);
  const Eigen::MatrixXd spd = a * a.transpose() + Eigen::MatrixXd::Identity(20, 20);
  const Eigen::VectorXd negative = -Eigen::VectorXd::Ones(20);
  const LemkeResult bounded = solve_lcp_lemke(spd, negative, 3, &z);
  EXPECT_EQ(bounded.outcome, LemkeOutcome::kPivotLimit);
  EXPECT_LE(bounded.pivots, 3);
}

// Small stacks: the exact solver and well-converged PGS reach the same resting state.
TEST(Solvers, ExactAndPgsAgreeOnSmallStacks) {
  for (int height : {1, 2, 3}) {
    std::vector<Vec3> final_positions[2];
    double impulses[2] = {0, 0};
    int k = 0;
    for (SolverKind kind : {SolverKind::kExact, SolverKind::kPgs}) {
      SceneDef scene = tower_scene(height);
      // Start each box 1 cm up and turned a little, so the solvers have something to do.
      for (std::size_t i = 1; i < scene.bodies.size(); ++i) {
        scene.bodies[i].position.z() += 0.01 * i;
        scene.bodies[i].orientation = Quat(Eigen::AngleAxisd(0.05 * i, Vec3::UnitZ()));
      }
      scene.world.solver.kind = kind;
      scene.world.solver.iterations = 100;
      scene.world.solver.sleeping = false;  // the impulses are compared at the end
      World world = build(scene);
      run(world, 1.0 / 60, 120);
      for (const BodyView b : dynamic_bodies(world))
        final_positions[k].push_back(b->position());
      for (double impulse : world.contact_impulses())
        impulses[k] += impulse;
      EXPECT_EQ(world.last_step().exact_fallbacks, 0u);
      ++k;
    }
    SCOPED_TRACE("tower of " + std::to_string(height));
    for (std::size_t i = 0; i < final_positions[0].size(); ++i)
      EXPECT_LT((final_positions[0][i] - final_positions[1][i]).norm(), 2e-3);
    // The contact impulses carry the stack's weight in both: n g dt per step on the ground.
    const double weight = height * 9.81 / 60;
    EXPECT_NEAR(impulses[0], impulses[1], 0.02 * impulses[0]);
    EXPECT_GT(impulses[0], weight);
  }
}

// Frictionless contact on a slope-free floor: no friction rows are built, and the LCP is only
// the normals (a scene pays only for what it uses).
TEST(Solvers, ExactSolverSkipsFrictionRowsWhenFrictionless) {
  SceneDef scene = tower_scene(2);
  for (BodyDef& def : scene.bodies)
    def.friction = 0;
  scene.world.solver.kind = SolverKind::kExact;
  World world = build(scene);
  run(world, 1.0 / 60, 10);
  const StepStats& stats = world.last_step();
  // Normals only: the pivots cannot exceed a few per contact point.
  EXPECT_LE(stats.lemke_pivots, 4u * stats.contact_points);
  EXPECT_EQ(stats.exact_fallbacks, 0u);
}

}  // namespace
}  // namespace tumble::testing
