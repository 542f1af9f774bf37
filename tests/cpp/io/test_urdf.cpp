// SPDX-License-Identifier: BSD-3-Clause
// URDF import (armdyn/io/urdf.hpp): tests/data/urdf/arm6.urdf against figures read from the file
// by hand (masses, joint origins composed along the chain), an inline URDF with a rotated
// inertial frame, and malformed files raising UrdfError.
#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "armdyn/errors.hpp"
#include "armdyn/io/urdf.hpp"
#include "armdyn/math/quaternion.hpp"
#include "check.hpp"
#include "models.hpp"

using namespace armdyn;

namespace {

const std::string kArm6 = std::string(armdyn_test::kDataDir) + "/urdf/arm6.urdf";

std::string read_file(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

/// World position of joint j's point at the assembled state.
Vec3 joint_point_world(const Model& m, int j) {
  const Joint& jt = m.joints[j];
  if (jt.parent == kGround) return jt.point_parent;
  const Vec3 x = m.u0.segment<3>(7 * jt.parent);
  const Mat3 r = quat_to_rot(m.u0.segment<4>(7 * jt.parent + 3));
  return x + r * jt.point_parent;
}

}  // namespace

TEST_CASE(arm6_bodies_masses_and_joint_order) {
  const std::string text = read_file(kArm6);
  CHECK(!text.empty());
  // the file's own figures: every <mass value>, and the revolute joints in document order
  double total = 0.0;
  const std::regex mass_re("<mass value=\"([0-9.eE+-]+)\"");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), mass_re);
       it != std::sregex_iterator(); ++it)
    total += std::stod((*it)[1]);
  std::vector<std::string> revolute;
  const std::regex joint_re("<joint name=\"([^\"]+)\" type=\"revolute\"");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), joint_re);
       it != std::sregex_iterator(); ++it)
    revolute.push_back((*it)[1]);
  CHECK(revolute.size() == 6);

  const ModelPtr m = urdf_builder(kArm6, true, Vec3(0, 0, -9.81)).finalize();
  // base_link_inertia (4 kg) is fixed to the root: ground. wrist_3, flange and tool0 merge.
  CHECK(m->nb == 6);
  CHECK(m->coords.size() == 6);
  for (size_t k = 0; k < revolute.size() && k < m->coords.size(); ++k)
    CHECK(m->coords[k].name == revolute[k]);
  double model_mass = 0.0;
  for (const Body& b : m->bodies) model_mass += b.mass;
  CHECK_NEAR(model_mass, total - 4.0, 1e-12);
  CHECK_NEAR(m->bodies[m->find_body("wrist_3_link")].mass, 0.1879 + 0.35, 1e-12);
  CHECK(m->joint_tree);
  CHECK(m->mobility == 6);

  // joint points composed by hand along the chain: base R_z(pi), shoulder_pan at z = 0.089159
  // turned by R_z(pi) again (identity), shoulder_lift 0.13585 along y, then R_y(pi/2) maps the
  // elbow's origin (0, -0.1197, 0.425) to (0.425, -0.1197, 0)
  CHECK_MAT_NEAR(joint_point_world(*m, m->find_joint("shoulder_pan_joint")), Vec3(0, 0, 0.089159),
                 1e-12);
  CHECK_MAT_NEAR(joint_point_world(*m, m->find_joint("shoulder_lift_joint")),
                 Vec3(0, 0.13585, 0.089159), 1e-12);
  CHECK_MAT_NEAR(joint_point_world(*m, m->find_joint("elbow_joint")),
                 Vec3(0.425, 0.13585 - 0.1197, 0.089159), 1e-12);
  CHECK_MAT_NEAR(joint_point_world(*m, m->find_joint("wrist_1_joint")),
                 Vec3(0.425 + 0.39225, 0.13585 - 0.1197, 0.089159), 1e-12);

  // floating base: the root group is a free body
  const ModelPtr f = urdf_builder(kArm6, false, Vec3(0, 0, -9.81)).finalize();
  CHECK(f->nb == 7);
  CHECK(f->joints[f->find_joint("root_free")].type == JointType::Free);
  double floating_mass = 0.0;
  for (const Body& b : f->bodies) floating_mass += b.mass;
  CHECK_NEAR(floating_mass, total, 1e-12);
}

TEST_CASE(inline_xml_with_rotated_inertial_frame) {
  // a link hanging from a hinge at z = 1; its inertial frame is turned by pi/2 about z, so in
  // the link's axes Ixx and Iyy swap; the centre of mass is 0.5 below the joint
  const std::string xml = R"(
    <robot name="p">
      <link name="base"/>
      <link name="arm">
        <inertial>
          <origin xyz="0 0 -0.5" rpy="0 0 1.5707963267948966"/>
          <mass value="2.0"/>
          <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.25"/>
        </inertial>
      </link>
      <joint name="hinge" type="continuous">
        <parent link="base"/>
        <child link="arm"/>
        <origin xyz="0 0 1"/>
        <axis xyz="0 1 0"/>
      </joint>
    </robot>)";
  const ModelPtr m = urdf_builder(xml, true, Vec3(0, 0, -9.81)).finalize();
  CHECK(m->nb == 1);
  CHECK_NEAR(m->bodies[0].mass, 2.0, 0.0);
  CHECK_MAT_NEAR(m->u0.head<3>(), Vec3(0, 0, 0.5), 1e-14);
  // inertia in body axes: the body frame is the link frame at assembly (identity orientation)
  const Mat3 r = quat_to_rot(m->u0.segment<4>(3));
  const Mat3 world_inertia = r * m->bodies[0].inertia * r.transpose();
  CHECK_MAT_NEAR(world_inertia, Vec3(0.2, 0.1, 0.25).asDiagonal().toDenseMatrix(), 1e-14);
  // continuous joint: unbounded
  CHECK(m->joints[0].type == JointType::Revolute);
  CHECK(m->joints[0].upper > 1e100);
}

TEST_CASE(malformed_files_raise_urdf_error) {
  const std::string dir = std::string(armdyn_test::kDataDir) + "/urdf/";
  const Vec3 g(0, 0, -9.81);
  const std::string syntax =
      THROWN_MESSAGE(urdf_builder(dir + "bad_syntax.urdf", true, g), UrdfError);
  CHECK(!syntax.empty());
  CHECK_THROWS(urdf_builder(dir + "bad_floating.urdf", true, g), UrdfError);
  // a massless leaf link: its joint's motion carries no inertia (refused at finalize, naming
  // the joint and the link)
  const std::string massless = THROWN_MESSAGE(
      urdf_builder(dir + "bad_massless_moving.urdf", true, g).finalize(), ModelError);
  CHECK(massless.find("'wrist'") != std::string::npos);
  CHECK(massless.find("'hand'") != std::string::npos);
  CHECK_THROWS(urdf_builder(dir + "does_not_exist.urdf", true, g), UrdfError);
  CHECK_THROWS(urdf_builder("<robot name=\"x\"><link name=\"a\"></robot>", true, g), UrdfError);
  // UrdfError is a ModelError (Python ValueError)
  CHECK_THROWS(urdf_builder(dir + "bad_syntax.urdf", true, g), ModelError);
}

TEST_CASE(hardening_and_joint_dynamics) {
  const Vec3 g(0, 0, -9.81);
  auto pendulum = [](const std::string& inertia_ixx, const std::string& dynamics) {
    return "<robot name=\"p\"><link name=\"base\"/><link name=\"bob\"><inertial>"
           "<origin xyz=\"0 0 -0.5\"/><mass value=\"1\"/><inertia ixx=\"" +
           inertia_ixx +
           "\" ixy=\"0\" ixz=\"0\" iyy=\"0.02\" iyz=\"0\" izz=\"0.015\"/></inertial>"
           "</link><joint name=\"hinge\" type=\"continuous\"><parent link=\"base\"/>"
           "<child link=\"bob\"/><axis xyz=\"0 1 0\"/>" +
           dynamics + "</joint></robot>";
  };
  // urdfdom would read nan as 0: refused first, naming link, element and attribute
  const std::string nan = THROWN_MESSAGE(urdf_builder(pendulum("nan", ""), true, g), UrdfError);
  CHECK(nan.find("link 'bob'") != std::string::npos);
  CHECK(nan.find("<inertial><inertia> attribute 'ixx' is not finite") != std::string::npos);
  const std::string big = THROWN_MESSAGE(urdf_builder(pendulum("1e400", ""), true, g), UrdfError);
  CHECK(big.find("out of the range of a double") != std::string::npos);
  // devices are refused before they are opened
  const std::string dev = THROWN_MESSAGE(urdf_builder("/dev/zero", true, g), UrdfError);
  CHECK(dev.find("character device") != std::string::npos);
  // <dynamics> is joint friction on the joint's coordinate
  const ModelPtr m =
      urdf_builder(pendulum("0.03", "<dynamics damping=\"0.25\" friction=\"0.5\"/>"), true, g)
          .finalize();
  CHECK(m->coord_forces.size() == 1);
  CHECK(m->coord_forces[0].coord == 0);
  CHECK(m->coord_forces[0].damping == 0.25);
  CHECK(m->coord_forces[0].coulomb == 0.5);
  CHECK(m->coord_forces[0].v_smooth == kUrdfCoulombSmoothing);
  // no moving joint with a fixed base: a zero-DOF model
  const ModelPtr empty =
      urdf_builder(
          "<robot name=\"s\"><link name=\"a\"><inertial><mass value=\"1\"/>"
          "<inertia ixx=\"1\" ixy=\"0\" ixz=\"0\" iyy=\"1\" iyz=\"0\" izz=\"1\"/>"
          "</inertial></link></robot>",
          true, g)
          .finalize();
  CHECK(empty->nb == 0 && empty->coords.empty());
}

ARMDYN_TEST_MAIN()
