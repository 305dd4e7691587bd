// Uses the installed headers: builds a cloud through the traits and checks a property.
#include <Eigen/Core>
#include <cstdio>
#include <vector>

#include "ulc/core/cloud.hpp"

int main() {
  std::vector<Eigen::Vector3d> cloud = {{1, 2, 3}, {4, 5, 6}};
  ulc::PointCloud<float> soa;
  ulc::traits::resize(soa, ulc::traits::size(cloud));
  for (std::size_t i = 0; i < cloud.size(); ++i)
    ulc::traits::set_point(soa, i, ulc::traits::point(cloud, i).cast<float>());
  const bool ok = soa.size() == 2 && soa.points[1].z() == 6.0f;
  std::printf("consumer: %s\n", ok ? "ok" : "WRONG");
  return ok ? 0 : 1;
}
