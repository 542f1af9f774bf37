// SPDX-License-Identifier: BSD-3-Clause
// ModelBuilder (armdyn/builder/builder.hpp): sizes, topology, assembly and input validation.
#include <cmath>

#include "armdyn/builder/builder.hpp"
#include "armdyn/errors.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;
using armdyn_test::kIdentityQuat;

TEST_CASE(two_link_arm_sizes_and_topology) {
  const ModelPtr m = armdyn_test::TwoLink().model();
  CHECK(m->nb == 2);
  CHECK(m->nq == 7 * 2);
  CHECK(m->nv == 6 * 2);
  CHECK(m->nc == 2 * joint_rows(JointType::Revolute));
  CHECK(m->nc == 10);
  CHECK(m->nc_joint == m->nc);
  CHECK(m->mobility == 2);
  CHECK(m->is_tree);
  CHECK(m->joint_tree);
  CHECK(m->joint_path_reason().empty());
  CHECK(!m->redundant);
  CHECK(m->coords.size() == 2);
  CHECK(m->coords[0].name == "shoulder" && m->coords[1].name == "elbow");
  CHECK(m->find_body("link2") == 1);
  CHECK(m->find_body("ground") == kGround);
  CHECK(m->find_joint("elbow") == 1);
  CHECK_THROWS(m->find_body("nope"), ModelError);
  CHECK_THROWS(m->find_joint("nope"), ModelError);
  // the assembled state is the pose given to the builder (already consistent)
  CHECK_MAT_NEAR(m->u0.segment<3>(7), Vec3(0.7 + 0.3, 0, 0), 1e-14);
  CHECK_MAT_NEAR(m->u0.segment<4>(3), kIdentityQuat, 1e-14);
  CHECK(m->v0.size() == m->nv && m->v0.norm() == 0.0);
}

TEST_CASE(joint_types_rows_and_coordinates) {
  // rows: 6 - freedoms; coordinates: angles and displacements
  CHECK(joint_rows(JointType::Revolute) == 5 && joint_coords(JointType::Revolute) == 1);
  CHECK(joint_rows(JointType::Prismatic) == 5 && joint_coords(JointType::Prismatic) == 1);
  CHECK(joint_rows(JointType::Cylindrical) == 4 && joint_coords(JointType::Cylindrical) == 2);
  CHECK(joint_rows(JointType::Spherical) == 3 && joint_coords(JointType::Spherical) == 0);
  CHECK(joint_rows(JointType::Universal) == 4);
  CHECK(joint_rows(JointType::Fixed) == 6);
  CHECK(joint_rows(JointType::Free) == 0);
  CHECK(joint_rows(JointType::Inline) == 2);
  CHECK(joint_rows(JointType::Distance) == 1);
}

TEST_CASE(closed_loop_mobility) {
  // planar four-bar (hinges about y) closed by an inline joint: 3 bodies, 18 velocities,
  // 5 + 5 + 5 + 2 independent rows, one degree of freedom; not a tree
  ModelBuilder b;
  const Mat3 in = Vec3(0.01, 0.02, 0.01).asDiagonal();
  b.add_body("crank", 1.0, in, Vec3(0, 0, 0.25), kIdentityQuat);
  b.add_body("coupler", 1.0, in, Vec3(0.5, 0, 0.5), kIdentityQuat);
  b.add_body("rocker", 1.0, in, Vec3(1.0, 0, 0.3), kIdentityQuat);
  b.add_revolute("A", "ground", "crank", Vec3(0, 0, 0), Vec3::UnitY());
  b.add_revolute("B", "crank", "coupler", Vec3(0, 0, 0.5), Vec3::UnitY());
  b.add_revolute("D", "ground", "rocker", Vec3(1, 0, 0.1), Vec3::UnitY());
  b.add_inline("C", "rocker", "coupler", Vec3(1, 0, 0.5), Vec3::UnitY());
  const ModelPtr m = b.finalize();
  CHECK(m->nc == 17);
  CHECK(m->mobility == 1);
  CHECK(!m->redundant);
  CHECK(!m->is_tree);
  CHECK(!m->joint_path_reason().empty());
  // a drive on the crank leaves nothing free
  b.add_drive("A", Profile::constant(0.0));
  const ModelPtr driven = b.finalize();
  CHECK(driven->nc == 18 && driven->nc_joint == 17);
  CHECK(driven->mobility_driven == 0);
}

TEST_CASE(assembly_solves_the_drives_at_t0) {
  // joint coordinates are 0 at the pose given to the builder; a drive holding the hinge at 0.4
  // makes finalize() turn the pendulum there: centre of mass at R_y(0.4) (0, 0, -L)
  const armdyn_test::Pendulum p;
  ModelBuilder b = p.builder();
  b.add_drive("hinge", Profile::constant(0.4));
  const ModelPtr m = b.finalize();
  CHECK_MAT_NEAR(m->u0.head<3>(), Vec3(-p.L * std::sin(0.4), 0.0, -p.L * std::cos(0.4)), 1e-12);
  CHECK_MAT_NEAR(m->u0.segment<4>(3), quat_exp(Vec3(0, 0.4, 0)), 1e-12);
  CHECK(m->mobility == 1 && m->mobility_driven == 0);
}

TEST_CASE(invalid_input_throws_and_leaves_the_builder_unchanged) {
  ModelBuilder b;
  const Mat3 in = Vec3(0.1, 0.1, 0.1).asDiagonal();
  b.add_body("a", 1.0, in, Vec3::Zero(), kIdentityQuat);
  CHECK_THROWS(b.add_body("a", 1.0, in, Vec3::Zero(), kIdentityQuat), ModelError);  // duplicate
  CHECK_THROWS(b.add_body("b", -1.0, in, Vec3::Zero(), kIdentityQuat), ModelError);
  CHECK_THROWS(b.add_body("b", NAN, in, Vec3::Zero(), kIdentityQuat), ModelError);
  CHECK_THROWS(b.add_body("ground", 1.0, in, Vec3::Zero(), kIdentityQuat), ModelError);
  // not positive definite; triangle inequality violated (Ixx > Iyy + Izz)
  CHECK_THROWS(b.add_body("b", 1.0, Vec3(-0.1, 0.1, 0.1).asDiagonal(), Vec3::Zero(), kIdentityQuat),
               ModelError);
  CHECK_THROWS(b.add_body("b", 1.0, Vec3(0.5, 0.1, 0.1).asDiagonal(), Vec3::Zero(), kIdentityQuat),
               ModelError);
  CHECK_THROWS(b.add_body("b", 1.0, in, Vec3(NAN, 0, 0), kIdentityQuat), ModelError);
  CHECK_THROWS(b.add_revolute("j", "ground", "missing", Vec3::Zero(), Vec3::UnitZ()), ModelError);
  CHECK_THROWS(b.add_revolute("j", "a", "a", Vec3::Zero(), Vec3::UnitZ()), ModelError);
  CHECK_THROWS(b.add_revolute("j", "ground", "a", Vec3::Zero(), Vec3::Zero()), ModelError);
  CHECK(b.draft().bodies.size() == 1);
  CHECK(b.draft().joints.empty());
  // a body without a joint to ground
  b.add_body("loose", 1.0, in, Vec3(1, 0, 0), kIdentityQuat);
  b.add_revolute("j", "ground", "a", Vec3::Zero(), Vec3::UnitZ());
  const std::string why = THROWN_MESSAGE(b.finalize(), ModelError);
  CHECK(why.find("loose") != std::string::npos);
  // no bodies: a zero-DOF model (a URDF structure fixed to ground)
  const ModelPtr empty = ModelBuilder().finalize();
  CHECK(empty->nb == 0 && empty->nq == 0 && empty->nv == 0 && empty->nc == 0);
  CHECK(empty->coords.empty() && empty->mobility == 0);
}

TEST_CASE(check_inertia_names_its_verdict) {
  // the kind decides add_body's message; the words are what the URDF reader quotes
  const InertiaCheck ok = check_inertia(Vec3(0.1, 0.2, 0.25).asDiagonal(), true);
  CHECK(ok.kind == InertiaProblem::None && ok.problem.empty());
  const InertiaCheck tri = check_inertia(Vec3(0.5, 0.1, 0.1).asDiagonal(), true);
  CHECK(tri.kind == InertiaProblem::TriangleInequality);
  CHECK(tri.problem == "violates the triangle inequality");
  const InertiaCheck neg = check_inertia(Vec3(-0.1, 0.1, 0.1).asDiagonal(), true);
  CHECK(neg.kind == InertiaProblem::NotPositiveSemidefinite);
  CHECK(neg.problem == "is not positive semidefinite");
  // physical = false accepts the triangle violation, not a negative moment
  CHECK(check_inertia(Vec3(0.5, 0.1, 0.1).asDiagonal(), false).kind == InertiaProblem::None);
  CHECK(check_inertia(Vec3(-0.1, 0.1, 0.1).asDiagonal(), false).kind ==
        InertiaProblem::NotPositiveSemidefinite);
  ModelBuilder b;
  const std::string why = THROWN_MESSAGE(
      b.add_body("b", 1.0, Vec3(0.5, 0.1, 0.1).asDiagonal(), Vec3::Zero(), kIdentityQuat),
      ModelError);
  CHECK(why.find("body 'b': inertia violates the triangle inequality (principal moments ") == 0);
  CHECK(why.find(" < 0.5); physical_inertia=False accepts") != std::string::npos);
}

ARMDYN_TEST_MAIN()
