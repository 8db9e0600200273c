#include "mass_integrals.h"

namespace tumble {

PolyhedronIntegrals integrate_polyhedron(const ConvexPolyhedron& polyhedron) {
  // Tetrahedra from the vertex mean keep the summands small, so nothing cancels badly.
  Vec3 reference = Vec3::Zero();
  for (const Vec3& v : polyhedron.vertices)
    reference += v;
  reference /= static_cast<double>(polyhedron.vertices.size());

  // The covariance of the unit tetrahedron (0, e1, e2, e3) scaled by its determinant.
  Mat3 canonical;
  canonical << 2, 1, 1, 1, 2, 1, 1, 1, 2;
  canonical /= 120.0;

  double volume = 0;
  Vec3 first_moment = Vec3::Zero();
  Mat3 covariance = Mat3::Zero();
  for (const auto& face : polyhedron.faces) {
    const Vec3 a = polyhedron.face_vertex(face, 0) - reference;
    for (std::uint32_t k = 1; k + 1 < face.count; ++k) {
      const Vec3 b = polyhedron.face_vertex(face, k) - reference;
      const Vec3 c = polyhedron.face_vertex(face, k + 1) - reference;
      Mat3 columns;
      columns << a, b, c;
      const double det = columns.determinant();
      volume += det / 6.0;
      first_moment += det / 24.0 * (a + b + c);
      covariance += det * columns * canonical * columns.transpose();
    }
  }
  PolyhedronIntegrals out;
  out.volume = volume;
  if (volume <= 0) return out;
  const Vec3 centroid_offset = first_moment / volume;
  out.centroid = reference + centroid_offset;
  // Parallel-axis shift of the covariance from the reference point to the centroid.
  out.second_moment = covariance - volume * centroid_offset * centroid_offset.transpose();
  return out;
}

Mat3 inertia_from_second_moment(const Mat3& second_moment, double density) {
  const Mat3 c = density * second_moment;
  return Mat3::Identity() * c.trace() - c;
}

}  // namespace tumble
