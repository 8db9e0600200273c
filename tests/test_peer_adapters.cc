// The peers' adapters (bench/peers/) simulate the bodies ours does: here Bullet's compounds whose
// centre of mass is off their frame's origin and whose axes are not principal (Bullet's body frame
// is both), placed where ours are and coming to rest as the geometry says.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "peers/simulation.h"
#include "scenes/scene.h"

namespace tumble::bench {
namespace {

// An L of two bars with a ball at its foot, dropped turned 30 degrees about y: its centre of mass
// (0.089, 0.016, 0.168) m off its frame's origin, its inertia tensor not diagonal.
constexpr char kDroppedL[] = R"({"bodies": [
    {"shape": "plane"},
    {"shape": "compound", "mass": 3, "position": [0.2, -0.1, 0.8],
     "orientation": [0.9659258262890683, 0.0, 0.25881904510252074, 0.0],
     "parts": [{"shape": "box", "size": [1.0, 0.2, 0.2]},
               {"shape": "box", "size": [0.2, 0.3, 0.6], "position": [0.4, 0, 0.4]},
               {"shape": "sphere", "radius": 0.15, "position": [-0.45, 0.1, 0.05]}]}]})";

TEST(PeerAdapters, BulletPlacesACompoundOffItsCentreWhereOursIsAndRestsItOnItsBar) {
  const SceneDef scene = parse_scene(kDroppedL).value();
  const PeerScene peer = peer_scene(scene);
  const Vec3 centre = peer.centre_of_mass[1];
  ASSERT_GT(centre.norm(), 0.1);
  const Mat3& tensor = peer.inertia_tensor[1];
  ASSERT_GT(std::abs(tensor(0, 2)), 1e-3 * tensor.diagonal().maxCoeff());
  std::string why_not;
  std::unique_ptr<Simulation> ours = make_tumble(scene, &why_not);
  ASSERT_NE(ours, nullptr) << why_not;
  int compared = 0;
  for (bool twice : {false, true}) {
    std::unique_ptr<Simulation> bullet =
        twice ? make_bullet_double(peer, {}, &why_not) : make_bullet(peer, {}, &why_not);
    if (bullet == nullptr) {
      ASSERT_NE(why_not.find("not built"), std::string::npos) << why_not;
      continue;
    }
    ++compared;
    // Where ours starts: its centre of mass, the shape's frame's orientation.
    const double rounding = twice ? 1e-12 : 1e-6;
    const BodyState start = bullet->body(0), expected = ours->body(0);
    EXPECT_LT((start.position - expected.position).norm(), rounding) << bullet->engine();
    EXPECT_LT(start.orientation.angularDistance(expected.orientation), rounding)
        << bullet->engine();
    for (int k = 0; k < 240; ++k)
      ASSERT_TRUE(bullet->step());
    // At rest on the long bar (0.2 m thick), upright part up: the centre of mass at the bar's
    // half thickness plus its height in the frame, the frame's z vertical.
    const BodyState rest = bullet->body(0);
    EXPECT_NEAR(rest.position.z(), 0.1 + centre.z(), 2e-3) << bullet->engine();
    EXPECT_GT((rest.orientation * Vec3::UnitZ()).z(), std::cos(1.0 * M_PI / 180))
        << bullet->engine();
    EXPECT_LT(rest.linear_velocity.norm(), 0.01) << bullet->engine();
  }
  if (compared == 0) GTEST_SKIP() << "Bullet is not built in: " << why_not;
  // Ours comes to rest the same way.
  for (int k = 0; k < 240; ++k)
    ASSERT_TRUE(ours->step());
  EXPECT_NEAR(ours->body(0).position.z(), 0.1 + centre.z(), 2e-3);
  EXPECT_GT((ours->body(0).orientation * Vec3::UnitZ()).z(), std::cos(1.0 * M_PI / 180));
}

}  // namespace
}  // namespace tumble::bench
