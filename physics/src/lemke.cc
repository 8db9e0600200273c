#include "lemke.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "wide.h"

namespace tumble {
namespace {

using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Row i of the row-major n x n `rows` minus column[i] times row `pivot_row`, for every other row
// with column[i] != 0: the pivot's elimination, where Lemke's time goes (half of an exact
// island's solve). Four doubles at a time in the AVX2 clone; element by element the same
// operation as Eigen's row update (a - c * b, no fused multiply-add), so the same bits on any
// machine.
TUMBLE_PER_CPU
void eliminate(double* rows, int n, int pivot_row, const double* column) {
  const double* pivot = rows + static_cast<std::ptrdiff_t>(pivot_row) * n;
  for (int i = 0; i < n; ++i) {
    if (i == pivot_row || column[i] == 0) continue;
    double* target = rows + static_cast<std::ptrdiff_t>(i) * n;
    const Wide factor = wide(column[i]);
    int k = 0;
    for (; k + kWideLanes <= n; k += kWideLanes) {
      Wide a, b;
      std::memcpy(&a, target + k, sizeof a);
      std::memcpy(&b, pivot + k, sizeof b);
      a = a - factor * b;
      std::memcpy(target + k, &a, sizeof a);
    }
    for (; k < n; ++k)
      target[k] -= column[i] * pivot[k];
  }
}

// Variables are numbered w_0..w_{n-1}, z_0..z_{n-1}, then the artificial z0 (index 2n). The
// tableau lives in the caller's workspace, so repeated solves allocate nothing.
struct Tableau {
  int n;
  // B^-1 of the current basis, row-major: every pivot subtracts whole rows.
  Eigen::Map<RowMajorMatrix> basis_inverse;
  Eigen::Map<Eigen::VectorXd> values;  // values of the basic variables, B^-1 q
  int* basic;                          // which variable each row holds

  // The entering variable's column in the current basis: B^-1 a, with the original columns
  // a(w_i) = e_i, a(z_j) = -M e_j, a(z0) = -1.
  void column(const Eigen::Ref<const Eigen::MatrixXd>& m, int variable,
              Eigen::Map<Eigen::VectorXd>& out) const {
    if (variable < n)
      out = basis_inverse.col(variable);
    else if (variable < 2 * n) {
      // In two steps: Eigen evaluates the negated product into a temporary of the heap.
      out.noalias() = basis_inverse * m.col(variable - n);
      out = -out;
    } else
      out = -basis_inverse.rowwise().sum();
  }

  void pivot(int row, int entering, const Eigen::Map<Eigen::VectorXd>& column) {
    const double p = column[row];
    basis_inverse.row(row) /= p;
    values[row] /= p;
    eliminate(basis_inverse.data(), n, row, column.data());
    for (int i = 0; i < n; ++i) {
      if (i == row || column[i] == 0) continue;
      values[i] -= column[i] * values[row];
    }
    basic[row] = entering;
  }
};

// True when row i's ratio vector (value, B^-1 row) / column[i] is lexicographically smaller
// than row j's.
bool lexicographically_smaller(const Tableau& t, const Eigen::Map<Eigen::VectorXd>& column, int i,
                               int j) {
  const double ri = t.values[i] / column[i], rj = t.values[j] / column[j];
  const double scale = 1e-12 * std::max({1.0, std::abs(ri), std::abs(rj)});
  if (std::abs(ri - rj) > scale) return ri < rj;
  for (int k = 0; k < t.n; ++k) {
    const double ai = t.basis_inverse(i, k) / column[i];
    const double aj = t.basis_inverse(j, k) / column[j];
    if (std::abs(ai - aj) > 1e-12 * std::max({1.0, std::abs(ai), std::abs(aj)})) return ai < aj;
  }
  return i < j;
}

}  // namespace

LemkeResult solve_lcp_lemke(const Eigen::MatrixXd& m, const Eigen::VectorXd& q, int max_pivots,
                            Eigen::VectorXd* z) {
  LemkeWorkspace workspace;
  z->resize(q.size());
  return solve_lcp_lemke(m, q, max_pivots, *z, &workspace);
}

LemkeResult solve_lcp_lemke(const Eigen::Ref<const Eigen::MatrixXd>& m,
                            const Eigen::Ref<const Eigen::VectorXd>& q, int max_pivots,
                            Eigen::Ref<Eigen::VectorXd> z, LemkeWorkspace* workspace) {
  const int n = static_cast<int>(q.size());
  z.setZero();
  LemkeResult result;
  if (!m.allFinite() || !q.allFinite()) {
    result.outcome = LemkeOutcome::kNotFinite;
    return result;
  }
  if (n == 0 || q.minCoeff() >= 0) return result;  // z = 0 already complements w = q

  const int artificial = 2 * n;
  workspace->basis_inverse.resize(static_cast<std::size_t>(n) * n);
  workspace->values.resize(n);
  workspace->column.resize(n);
  workspace->basic.resize(n);
  Tableau t{n, Eigen::Map<RowMajorMatrix>(workspace->basis_inverse.data(), n, n),
            Eigen::Map<Eigen::VectorXd>(workspace->values.data(), n), workspace->basic.data()};
  t.basis_inverse.setIdentity();
  t.values = q;
  for (int i = 0; i < n; ++i)
    t.basic[i] = i;
  Eigen::Map<Eigen::VectorXd> column(workspace->column.data(), n);

  // z0 enters at the level that makes every w non-negative; the most negative w leaves.
  int row = 0;
  for (int i = 1; i < n; ++i)
    if (q[i] < q[row]) row = i;
  int entering = artificial;
  t.column(m, entering, column);
  int leaving = t.basic[row];
  t.pivot(row, entering, column);
  ++result.pivots;

  while (true) {
    // The complement of the variable that just left enters.
    entering = leaving < n ? leaving + n : leaving - n;
    t.column(m, entering, column);
    const double tolerance = 1e-12 * std::max(1.0, column.cwiseAbs().maxCoeff());
    double min_ratio = std::numeric_limits<double>::infinity();
    for (int i = 0; i < n; ++i)
      if (column[i] > tolerance) min_ratio = std::min(min_ratio, t.values[i] / column[i]);
    row = -1;
    if (std::isfinite(min_ratio)) {
      const double tie = 1e-12 * std::max(1.0, std::abs(min_ratio));
      for (int i = 0; i < n; ++i) {
        if (column[i] <= tolerance || t.values[i] / column[i] > min_ratio + tie) continue;
        // z0 leaving ends the path: take it whenever it ties for the minimum ratio.
        if (t.basic[i] == artificial) {
          row = i;
          break;
        }
        if (row < 0 || lexicographically_smaller(t, column, i, row)) row = i;
      }
    }
    if (row < 0) {
      result.outcome = LemkeOutcome::kRayTermination;
      return result;
    }
    if (result.pivots >= max_pivots) {
      result.outcome = LemkeOutcome::kPivotLimit;
      return result;
    }
    leaving = t.basic[row];
    t.pivot(row, entering, column);
    ++result.pivots;
    if (leaving == artificial) break;
  }

  for (int i = 0; i < n; ++i) {
    const int variable = t.basic[i];
    if (variable >= n && variable < 2 * n) z[variable - n] = std::max(t.values[i], 0.0);
  }
  return result;
}

}  // namespace tumble
