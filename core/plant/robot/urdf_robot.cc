#include "core/plant/robot/urdf_robot.h"

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>

#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <locale>
#include <filesystem>
#include <map>
#include <mutex>
#include <sstream>

#include "core/base/json_input.h"
#include "core/base/suggest.h"
#include "core/plant/robot/mass_properties.h"

namespace armfault {

namespace {

constexpr int kMaxUrdfJoints = 7;
// The limits of a link and of the base in the robot JSON (robot_config.cc), for the URDF's
// bodies: every coordinate within 1000 m of the root, a body's mass up to 1000 kg, its
// moments up to 1e5 kg m^2.
constexpr double kMaxCoordinate_m = 1000;
constexpr double kMaxBodyMass_kg = 1000;
constexpr double kMaxBodyMoment_kg_m2 = 1e5;
// A URDF larger than this is not an arm description (real ones are well below 1 MB once
// meshes are separate files); refused before it is read into memory.
constexpr std::uintmax_t kMaxUrdfBytes = 16u << 20;

using Eigen::Matrix3d;
using Eigen::Vector3d;

struct Frame {
  Matrix3d rot = Matrix3d::Identity();
  Vector3d pos = Vector3d::Zero();
  Frame operator*(const Frame& o) const { return {rot * o.rot, rot * o.pos + pos}; }
};

Frame FrameOf(const urdf::Pose& p) {
  Frame f;
  f.pos = Vector3d(p.position.x, p.position.y, p.position.z);
  f.rot = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z).normalized().toRotationMatrix();
  return f;
}

bool Finite(const urdf::Pose& p) {
  return std::isfinite(p.position.x) && std::isfinite(p.position.y) && std::isfinite(p.position.z) &&
         std::isfinite(p.rotation.x) && std::isfinite(p.rotation.y) && std::isfinite(p.rotation.z) &&
         std::isfinite(p.rotation.w);
}

// urdfdom reports through console_bridge; while one parse runs, its messages are collected
// here instead of going to stderr (the parse is serialised: the handler is process-wide).
class CollectingHandler : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR && first_error.empty()) first_error = text;
  }
  std::string first_error;
};

// The numeric attributes of the elements armfault reads, with how many numbers each holds.
// urdfdom reads a value such as "1.0kg", "nan" or "abc" as 0 (or leaves the default) without a
// word, which later reads as "no mass" or "moment 0"; every one is checked here first.
struct NumericAttribute {
  const char* element;
  const char* attribute;
  int count;
};
constexpr NumericAttribute kNumericAttributes[] = {
    {"mass", "value", 1},       {"inertia", "ixx", 1}, {"inertia", "ixy", 1},     {"inertia", "ixz", 1},
    {"inertia", "iyy", 1},      {"inertia", "iyz", 1}, {"inertia", "izz", 1},     {"origin", "xyz", 3},
    {"origin", "rpy", 3},       {"axis", "xyz", 3},    {"limit", "lower", 1},     {"limit", "upper", 1},
    {"limit", "effort", 1},     {"limit", "velocity", 1}, {"dynamics", "damping", 1}, {"dynamics", "friction", 1},
    {"mimic", "multiplier", 1}, {"mimic", "offset", 1},
};

// Whether `text` is exactly `count` finite numbers separated by white space (one number: with
// no white space around it, which urdfdom would read as 0).
bool FiniteNumbers(const std::string& text, int count) {
  if (count == 1 && (text.empty() || std::isspace(static_cast<unsigned char>(text.front())) ||
                     std::isspace(static_cast<unsigned char>(text.back())))) {
    return false;
  }
  std::istringstream in(text);
  in.imbue(std::locale::classic());
  std::string token;
  int n = 0;
  while (in >> token) {
    double v = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
    if (ec != std::errc() || end != token.data() + token.size() || !std::isfinite(v)) return false;
    ++n;
  }
  return n == count;
}

// The element's place for a message: the enclosing <link> or <joint> by name, then the path.
std::string PlaceOf(const TiXmlElement* e) {
  std::string path;
  for (const TiXmlNode* n = e; n && n->ToElement(); n = n->Parent()) {
    const TiXmlElement* el = n->ToElement();
    const std::string tag = el->ValueStr();
    if ((tag == "link" || tag == "joint") && el->Attribute("name")) {
      return "<" + tag + " name=\"" + *el->Attribute(std::string("name")) + "\">" + path;
    }
    if (tag == "robot") break;
    path = "<" + tag + ">" + path;
  }
  return path.empty() ? "<robot>" : path;
}

// A value as it may be shown: quoted, at most 40 characters, control characters as '?'.
std::string ShownValue(const std::string& value) {
  std::string shown = value.substr(0, 40);
  for (char& c : shown) {
    if (static_cast<unsigned char>(c) < 0x20) c = '?';
  }
  return "\"" + shown + (value.size() > 40 ? "...\"" : "\"");
}

void CheckNumbers(const TiXmlElement* e, const std::string& name) {
  for (; e; e = e->NextSiblingElement()) {
    for (const NumericAttribute& a : kNumericAttributes) {
      if (e->ValueStr() != a.element) continue;
      const std::string* value = e->Attribute(std::string(a.attribute));
      if (!value || FiniteNumbers(*value, a.count)) continue;
      throw InputError(name, PlaceOf(e),
                       std::string(a.attribute) + "=" + ShownValue(*value) + ": expected " +
                           (a.count == 1 ? std::string("a finite number") : std::to_string(a.count) + " finite numbers") +
                           " (no units, no nan or inf)");
    }
    CheckNumbers(e->FirstChildElement(), name);
  }
}

// Every numeric attribute armfault reads is a finite number (InputError naming the element, the
// attribute and the value). A text TinyXML cannot read is left to urdfdom's own message.
void CheckUrdfNumbers(const std::string& text, const std::string& name) {
  TiXmlDocument doc;
  doc.Parse(text.c_str());
  if (doc.Error()) return;
  CheckNumbers(doc.RootElement(), name);
}

urdf::ModelInterfaceSharedPtr ParseUrdf(const std::string& text, const std::string& name) {
  CheckUrdfNumbers(text, name);
  static std::mutex mutex;
  std::lock_guard<std::mutex> lock(mutex);
  CollectingHandler handler;
  console_bridge::useOutputHandler(&handler);
  urdf::ModelInterfaceSharedPtr model;
  std::string thrown;
  try {
    model = urdf::parseURDF(text);
  } catch (const std::exception& e) {  // urdfdom throws for some malformed values
    thrown = e.what();
  }
  console_bridge::restorePreviousOutputHandler();
  if (!model) {
    std::string why = !thrown.empty() ? thrown : handler.first_error;
    if (why.empty()) why = "not a URDF robot";
    throw InputError(name, "<robot>", "urdfdom cannot read it: " + why);
  }
  return model;
}

// The merged mass properties of a body (world frame, zero pose).
struct MassSum {
  double mass = 0;
  Vector3d moment = Vector3d::Zero();  // sum m c
  std::vector<std::tuple<double, Vector3d, Matrix3d>> parts;  // mass, com, inertia about com

  void Add(double m, const Vector3d& com, const Matrix3d& inertia) {
    mass += m;
    moment += m * com;
    parts.emplace_back(m, com, inertia);
  }
  Vector3d Com() const { return moment / mass; }
  Matrix3d Inertia() const {
    const Vector3d c = Com();
    Matrix3d total = Matrix3d::Zero();
    for (const auto& [m, com, inertia] : parts) {
      const Vector3d r = com - c;
      total += inertia + m * (r.squaredNorm() * Matrix3d::Identity() - r * r.transpose());
    }
    return total;
  }
};

std::string Quote(const std::string& s) { return "\"" + s + "\""; }
// Where in the file an error is: the element, as the pointer of the message.
std::string JointElement(const std::string& name) { return "<joint name=\"" + name + "\">"; }
std::string LinkElement(const std::string& name) { return "<link name=\"" + name + "\">"; }

const char* JointTypeName(int type) {
  switch (type) {
    case urdf::Joint::PRISMATIC: return "prismatic";
    case urdf::Joint::FLOATING: return "floating";
    case urdf::Joint::PLANAR: return "planar";
    case urdf::Joint::REVOLUTE: return "revolute";
    case urdf::Joint::CONTINUOUS: return "continuous";
    case urdf::Joint::FIXED: return "fixed";
    default: return "unknown";
  }
}

bool Moving(const urdf::Joint& j) { return j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS; }

// A moving joint found in the tree walk, with its zero-pose frame and its body.
struct ChainJoint {
  urdf::JointConstSharedPtr joint;
  Frame frame;  // the child link's frame, world, zero pose
  MassSum body;
  std::vector<std::string> body_links;
  Vector3d tool_point = Vector3d::Zero();
};

class ChainBuilder {
 public:
  ChainBuilder(const urdf::ModelInterface& model, std::string name, const Vector3d& base)
      : model_(model), name_(std::move(name)) {
    base_.pos = base;
  }

  std::vector<ChainJoint> Build() {
    const urdf::LinkConstSharedPtr root = model_.getRoot();
    if (!root) throw InputError(name_, "<robot>", "the URDF has no root link");
    // A link that is the child of two joints closes a loop (urdfdom keeps one of them).
    std::map<std::string, std::string> parent_joint_of;
    for (const auto& [joint_name, joint] : model_.joints_) {
      const auto [it, fresh] = parent_joint_of.emplace(joint->child_link_name, joint_name);
      if (!fresh) {
        throw InputError(name_, LinkElement(joint->child_link_name),
                         "it is the child of joints " + Quote(it->second) + " and " + Quote(joint_name) +
                             ": a closed chain; armfault simulates serial arms only");
      }
    }
    // The base: the root and its fixed descendants, up to the first moving joints.
    std::vector<urdf::JointConstSharedPtr> next;
    WalkFixed(root, base_, nullptr, &next);
    while (!next.empty()) {
      if (next.size() > 1) {
        throw InputError(name_, "<robot>", "a branching tree: joints " + Quote(next[0]->name) + " and " + Quote(next[1]->name) +
                                        " both move below " + (chain_.empty() ? std::string("the base") : "joint " + Quote(chain_.back().joint->name)) +
                                        "; armfault simulates serial arms only");
      }
      const urdf::JointConstSharedPtr j = next[0];
      const urdf::LinkConstSharedPtr child = model_.getLink(j->child_link_name);
      ChainJoint cj;
      cj.joint = j;
      cj.frame = parent_frame_of_.at(j->name) * FrameOf(j->parent_to_joint_origin_transform);
      next.clear();
      chain_.push_back(cj);
      WalkFixed(child, cj.frame, &chain_.back(), &next);
      if (static_cast<int>(chain_.size()) > kMaxUrdfJoints) {
        throw InputError(name_, "<robot>", "more than " + std::to_string(kMaxUrdfJoints) + " moving joints (" + Quote(j->name) +
                                        " is the " + std::to_string(chain_.size()) + "th): armfault simulates arms of 1 to 7 joints");
      }
    }
    if (chain_.empty()) throw InputError(name_, "<robot>", "the URDF has no revolute or continuous joint: nothing moves");
    return chain_;
  }

 private:
  // Adds `link` (frame `f`) and its fixed descendants to `body` (null: the base); moving
  // joints below them go to `next`.
  void WalkFixed(const urdf::LinkConstSharedPtr& link, const Frame& f, ChainJoint* body,
                 std::vector<urdf::JointConstSharedPtr>* next) {
    if (body) {
      body->body_links.push_back(link->name);
      body->tool_point = f.pos;
      if (const auto& in = link->inertial) AddInertial(*link, *in, f, &body->body);
    }
    for (const urdf::JointSharedPtr& j : link->child_joints) {
      if (!Finite(j->parent_to_joint_origin_transform)) {
        throw InputError(name_, JointElement(j->name), "its <origin> has a value that is not a finite number");
      }
      if (j->type == urdf::Joint::FIXED) {
        WalkFixed(model_.getLink(j->child_link_name), f * FrameOf(j->parent_to_joint_origin_transform), body, next);
      } else if (Moving(*j)) {
        if (j->mimic) {
          throw InputError(name_, JointElement(j->name),
                           "it mimics joint " + Quote(j->mimic->joint_name) +
                               " (<mimic>): a joint that follows another has no drive of its own, which armfault does "
                               "not model; make it fixed, or remove the <mimic> and give it a drive");
        }
        parent_frame_of_[j->name] = f;
        next->push_back(j);
      } else {
        throw InputError(name_, JointElement(j->name), std::string("a ") + JointTypeName(j->type) + " joint" +
                                        ": only revolute, continuous and fixed joints are supported");
      }
    }
  }

  void AddInertial(const urdf::Link& link, const urdf::Inertial& in, const Frame& f, MassSum* sum) {
    const double values[] = {in.mass, in.ixx, in.ixy, in.ixz, in.iyy, in.iyz, in.izz};
    for (double v : values) {
      if (!std::isfinite(v)) {
        throw InputError(name_, LinkElement(link.name), "its <inertial> has a value that is not a finite number");
      }
    }
    if (!Finite(in.origin)) {
      throw InputError(name_, LinkElement(link.name), "its <inertial><origin> has a value that is not a finite number");
    }
    if (in.mass < 0) {
      throw InputError(name_, LinkElement(link.name), "mass " + FormatNumber(in.mass) + " kg is negative");
    }
    const Frame c = f * FrameOf(in.origin);
    Matrix3d inertia;
    inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    sum->Add(in.mass, c.pos, c.rot * inertia * c.rot.transpose());
  }

  const urdf::ModelInterface& model_;
  std::string name_;
  Frame base_;
  std::vector<ChainJoint> chain_;
  std::map<std::string, Frame> parent_frame_of_;
};

// <transmission> reductions by joint name (TinyXML, as urdfdom itself uses). ROS writes 1 as
// a placeholder in most published files (a joint-space interface): 1 means "not stated".
std::map<std::string, std::pair<std::string, double>> TransmissionReductions(const std::string& text) {
  std::map<std::string, std::pair<std::string, double>> out;
  TiXmlDocument doc;
  doc.Parse(text.c_str());
  const TiXmlElement* robot = doc.FirstChildElement("robot");
  for (const TiXmlElement* t = robot ? robot->FirstChildElement("transmission") : nullptr; t;
       t = t->NextSiblingElement("transmission")) {
    const char* tname = t->Attribute("name");
    const TiXmlElement* joint = t->FirstChildElement("joint");
    const char* jname = joint ? joint->Attribute("name") : nullptr;
    // Both forms: <actuator><mechanicalReduction> (ROS) and <mechanicalReduction> directly (old).
    const TiXmlElement* actuator = t->FirstChildElement("actuator");
    const TiXmlElement* red = actuator ? actuator->FirstChildElement("mechanicalReduction") : nullptr;
    if (!red) red = t->FirstChildElement("mechanicalReduction");
    if (!jname || !red || !red->GetText()) continue;
    char* end = nullptr;
    const double value = std::strtod(red->GetText(), &end);
    out[jname] = {tname ? tname : "", end && *end == '\0' ? value : std::nan("")};
  }
  return out;
}

// The drive of one joint from its drives entry (a type name or a module object).
ModuleParams DriveOf(const nlohmann::json& entry, const std::string& pointer, const urdf::Joint& joint,
                     ErrorList* errors) {
  if (!entry.is_string() && !entry.is_object()) {
    throw InputError("", pointer, "expected a drive type (e.g. \"industrial-small\") or a module object, got " + Describe(entry));
  }
  nlohmann::json module = entry.is_string() ? nlohmann::json{{"type", entry}} : entry;
  const bool range_given = module.is_object() && (module.contains("min_angle_deg") || module.contains("max_angle_deg"));
  ModuleParams m = DriveFromJson(module, pointer, errors);
  if (!range_given) {
    if (joint.type == urdf::Joint::REVOLUTE && joint.limits) {
      // More than a turn either way (or a rounding of 2 pi past it) is a full turn.
      m.min_angle_deg = std::max(-360.0, joint.limits->lower * 180.0 / M_PI);
      m.max_angle_deg = std::min(360.0, joint.limits->upper * 180.0 / M_PI);
    } else {
      m.min_angle_deg = -360;
      m.max_angle_deg = 360;
    }
  }
  const bool friction_given = module.is_object() && module.contains("friction");
  const auto& dyn = joint.dynamics;
  // Each value above 0 replaces its part (damping the viscous term, friction the Coulomb and
  // static ones); a value of 0, what most published files carry, leaves the drive type's.
  if (!friction_given && dyn) {
    const double ratio = m.drive.ratio;
    if (dyn->damping > 0 && std::isfinite(dyn->damping)) {
      m.friction.viscous_Nm_s_per_rad = dyn->damping / ratio;
      m.controller.b_hat = m.friction.viscous_Nm_s_per_rad;
    }
    if (dyn->friction > 0 && std::isfinite(dyn->friction)) {
      m.friction.coulomb_Nm = m.friction.static_Nm = dyn->friction / ratio;
      m.controller.fc_hat_Nm = m.controller.fs_hat_Nm = m.friction.coulomb_Nm;
      m.controller.ku_robust_Nm = m.friction.coulomb_Nm;  // the gain rule (docs/assumptions.md)
    }
  }
  return m;
}

std::array<double, 3> ReadPosition(const nlohmann::json& v, const std::string& pointer) {
  if (!v.is_array() || v.size() != 3) throw InputError("", pointer, "expected an array of 3 numbers, got " + Describe(v));
  std::array<double, 3> out{};
  for (size_t i = 0; i < 3; ++i) {
    out[i] = AsNumber(v[i], PointerJoin(pointer, i));
    RequireInRange(out[i], -1000, 1000, PointerJoin(pointer, i));
  }
  return out;
}

// `pointer`: the "urdf" key that names the file.
std::string ReadUrdfFile(const std::string& path, const std::string& pointer) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError("", pointer, "cannot read the URDF file \"" + path + "\": " + ec.message());
  if (size > kMaxUrdfBytes) {
    throw InputError("", pointer, "the URDF file \"" + path + "\" is " + std::to_string(size) + " bytes, more than the " +
                                   std::to_string(kMaxUrdfBytes) + " a robot description may have");
  }
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) throw InputError("", pointer, "cannot read the URDF file \"" + path + "\"");
  return text.str();
}

}  // namespace

RobotConfig RobotFromUrdfText(const std::string& text, const std::string& name, const nlohmann::json& drives,
                              const std::string& drives_pointer) {
  const urdf::ModelInterfaceSharedPtr model = ParseUrdf(text, name);
  const std::vector<ChainJoint> chain = ChainBuilder(*model, name, Vector3d::Zero()).Build();
  ErrorList errors;
  if (!drives.is_object()) {
    throw InputError("", drives_pointer, "expected an object naming a drive for each moving joint, got " + Describe(drives));
  }
  std::vector<std::string> joint_names;
  for (const ChainJoint& cj : chain) joint_names.push_back(cj.joint->name);
  for (const auto& item : drives.items()) {
    const std::string key = item.key();  // a named copy: lambdas below may not capture a binding
    if (std::find(joint_names.begin(), joint_names.end(), key) == joint_names.end()) {
      errors.Add(InputError("", PointerJoin(drives_pointer, key),
                            Quote(key) + " is not a moving joint of " + name + " (its joints: " + [&] {
                              std::string all;
                              for (const auto& n : joint_names) all += (all.empty() ? "" : ", ") + n;
                              return all;
                            }() + ")",
                            [&] {
                              const std::string near = NearestWord(key, joint_names);
                              return near.empty() ? std::string() : "did you mean \"" + near + "\"?";
                            }()));
    }
  }
  const auto reductions = TransmissionReductions(text);
  RobotConfig r;
  r.name = model->getName().empty() ? "urdf" : model->getName();
  for (const ChainJoint& cj : chain) {
    const urdf::Joint& j = *cj.joint;
    const std::string jp = PointerJoin(drives_pointer, j.name);
    ModuleParams m;
    if (!drives.contains(j.name)) {
      errors.Add(InputError("", drives_pointer, "no drive for joint " + Quote(j.name) + " of " + name +
                                                    ": name one (a type, e.g. \"industrial-small\", or an object)"));
    } else {
      errors.Try([&] { m = DriveOf(drives.at(j.name), jp, j, &errors); });
    }
    const auto red = reductions.find(j.name);
    if (red != reductions.end() && red->second.second != 1.0 &&
        !(std::fabs(red->second.second - m.drive.ratio) <= 1e-9 * m.drive.ratio)) {
      errors.Add(InputError(name, "<transmission name=\"" + red->second.first + "\">", "joint " + Quote(j.name) +
                                          " has a mechanicalReduction of " + FormatNumber(red->second.second) +
                                          ", the drive's ratio is " + FormatNumber(m.drive.ratio) +
                                          " (set drive/ratio in " + jp + " to match)"));
    }
    JointBody b;
    b.joint_name = j.name;
    const Vector3d axis_local(j.axis.x, j.axis.y, j.axis.z);
    if (!axis_local.allFinite() || axis_local.norm() < 1e-9) {
      errors.Add(InputError(name, JointElement(j.name), "its <axis> is zero or not finite"));
      continue;
    }
    const Vector3d axis = (cj.frame.rot * axis_local).normalized();
    b.axis = {axis.x(), axis.y(), axis.z()};
    b.anchor_m = {cj.frame.pos.x(), cj.frame.pos.y(), cj.frame.pos.z()};
    b.frame_origin_m = b.anchor_m;
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col) b.frame_rotation[3 * row + col] = cj.frame.rot(row, col);
    }
    const MassSum& s = cj.body;
    std::string links;
    for (const auto& l : cj.body_links) links += (links.empty() ? "" : ", ") + Quote(l);
    if (!(s.mass > 0)) {
      errors.Add(InputError(name, JointElement(j.name), "it moves link(s) " + links +
                                          " with no mass (no <inertial> with a mass above 0): a moving body needs one"));
      continue;
    }
    const Vector3d com = s.Com();
    const Matrix3d inertia = s.Inertia();
    // The robot input's physical limits (docs/assumptions.md): far beyond any arm, so that every
    // number ODE derives stays finite.
    if (!(cj.frame.pos.cwiseAbs().maxCoeff() <= kMaxCoordinate_m) || !(com.cwiseAbs().maxCoeff() <= kMaxCoordinate_m)) {
      errors.Add(InputError(name, JointElement(j.name), "the joint or its body's centre of mass lies more than " +
                                                           FormatNumber(kMaxCoordinate_m) + " m from the root"));
      continue;
    }
    if (!(s.mass <= kMaxBodyMass_kg) || !(inertia.cwiseAbs().maxCoeff() <= kMaxBodyMoment_kg_m2)) {
      errors.Add(InputError(name, JointElement(j.name), "the body it moves (link(s) " + links + ") weighs " +
                                                           FormatNumber(s.mass) + " kg with moments up to " +
                                                           FormatNumber(inertia.cwiseAbs().maxCoeff()) +
                                                           " kg m^2: beyond 1000 kg or 1e5 kg m^2"));
      continue;
    }
    b.mass_kg = s.mass;
    b.com_m = {com.x(), com.y(), com.z()};
    b.inertia_kg_m2 = {inertia(0, 0), inertia(1, 1), inertia(2, 2), inertia(0, 1), inertia(0, 2), inertia(1, 2)};
    const std::string problem = BodyMassProblem(s.mass, inertia);
    if (!problem.empty()) {
      errors.Add(InputError(name, JointElement(j.name), "the body it moves (link(s) " + links + "): its " + problem));
    }
    r.modules.push_back(m);
    r.bodies.push_back(b);
  }
  errors.ThrowIfAny();
  r.payload_point_m = {chain.back().tool_point.x(), chain.back().tool_point.y(), chain.back().tool_point.z()};
  return r;
}

std::vector<std::string> UrdfMovingJoints(const std::string& text, const std::string& name) {
  const urdf::ModelInterfaceSharedPtr model = ParseUrdf(text, name);
  std::vector<std::string> names;
  for (const ChainJoint& cj : ChainBuilder(*model, name, Vector3d::Zero()).Build()) names.push_back(cj.joint->name);
  return names;
}

RobotConfig RobotFromUrdfJson(const nlohmann::json& value, const std::string& pointer, const std::string& base_dir) {
  ObjectReader reader(value, pointer);
  ErrorList errors;
  errors.Try([&] {
    reader.AllowOnly({"name", "urdf", "drives", "base_position_m", "payload_kg", "gravity_m_s2", "physics_rate_Hz",
                      "electrical_substeps", "constraint_force_mixing", "engine"});
  });
  std::string path;
  reader.OptionalString("urdf", &path);
  if (path.empty()) throw InputError("", reader.PointerTo("urdf"), "expected the path of a URDF file, got \"\"");
  std::filesystem::path resolved(path);
  if (resolved.is_relative() && !base_dir.empty()) resolved = std::filesystem::path(base_dir) / resolved;
  const nlohmann::json& drives = reader.Require("drives");
  RobotConfig r = RobotFromUrdfText(ReadUrdfFile(resolved.string(), reader.PointerTo("urdf")), resolved.string(), drives, reader.PointerTo("drives"));
  Vector3d base = Vector3d::Zero();
  errors.Try([&] {
    if (const auto* v = reader.Find("base_position_m")) {
      const auto a = ReadPosition(*v, reader.PointerTo("base_position_m"));
      base = Vector3d(a[0], a[1], a[2]);
      r.base_position_m = a;
    }
  });
  errors.Try([&] { reader.OptionalString("name", &r.name); });
  errors.Try([&] { reader.OptionalNumber("payload_kg", &r.payload_kg); });
  errors.Try([&] { reader.OptionalNumber("gravity_m_s2", &r.gravity_m_s2); });
  errors.Try([&] { reader.OptionalNumber("physics_rate_Hz", &r.physics_rate_Hz); });
  errors.Try([&] { reader.OptionalInt("electrical_substeps", &r.electrical_substeps); });
  errors.Try([&] { reader.OptionalNumber("constraint_force_mixing", &r.constraint_force_mixing); });
  errors.Try([&] {
    if (const auto* v = reader.Find("engine")) r.engine = EngineFromJson(*v, reader.PointerTo("engine"));
  });
  errors.ThrowIfAny();
  // The base offset moves every body (the file's root frame sits at base_position_m).
  auto shift = [&](std::array<double, 3>* p) {
    for (int k = 0; k < 3; ++k) (*p)[k] += base[k];
  };
  for (JointBody& b : r.bodies) {
    shift(&b.anchor_m);
    shift(&b.com_m);
    shift(&b.frame_origin_m);
  }
  shift(&r.payload_point_m);
  return r;
}

std::string UrdfText(const RobotConfig& given) {
  const RobotConfig robot = WithBodies(given);
  const std::vector<JointBody>& bodies = robot.bodies;
  std::ostringstream out;
  out.precision(17);
  out << "<?xml version=\"1.0\"?>\n<!-- Written by armfault from robot \"" << robot.name
      << "\": one link per moving body, each link's frame at its joint's anchor with the world's axes at the zero pose. -->\n";
  out << "<robot name=\"" << robot.name << "\">\n  <link name=\"base\"/>\n";
  Vector3d prev = Vector3d::Zero();  // the file's root frame; base_position_m stays in the robot JSON
  const Vector3d base(robot.base_position_m[0], robot.base_position_m[1], robot.base_position_m[2]);
  std::string parent = "base";
  for (size_t i = 0; i < bodies.size(); ++i) {
    const JointBody& b = bodies[i];
    const ModuleParams& m = robot.modules[i];
    const Vector3d anchor = Vector3d(b.anchor_m[0], b.anchor_m[1], b.anchor_m[2]) - base;
    const Vector3d com = Vector3d(b.com_m[0], b.com_m[1], b.com_m[2]) - base - anchor;
    const std::string link = "link_" + std::to_string(i + 1);
    const auto& I = b.inertia_kg_m2;
    out << "  <link name=\"" << link << "\">\n    <inertial>\n      <origin xyz=\"" << com.x() << " " << com.y() << " "
        << com.z() << "\" rpy=\"0 0 0\"/>\n      <mass value=\"" << b.mass_kg << "\"/>\n      <inertia ixx=\"" << I[0]
        << "\" iyy=\"" << I[1] << "\" izz=\"" << I[2] << "\" ixy=\"" << I[3] << "\" ixz=\"" << I[4] << "\" iyz=\"" << I[5]
        << "\"/>\n    </inertial>\n  </link>\n";
    const Vector3d origin = anchor - prev;
    out << "  <joint name=\"" << b.joint_name << "\" type=\"revolute\">\n    <parent link=\"" << parent
        << "\"/>\n    <child link=\"" << link << "\"/>\n    <origin xyz=\"" << origin.x() << " " << origin.y() << " "
        << origin.z() << "\" rpy=\"0 0 0\"/>\n    <axis xyz=\"" << b.axis[0] << " " << b.axis[1] << " " << b.axis[2]
        << "\"/>\n    <limit lower=\"" << m.min_angle_deg * M_PI / 180.0 << "\" upper=\"" << m.max_angle_deg * M_PI / 180.0
        << "\" effort=\"" << m.motor.kt_Nm_per_A * m.inverter.command_limit_A * m.drive.ratio << "\" velocity=\""
        << m.inverter.bus_voltage_V / (m.motor.kt_Nm_per_A * m.drive.ratio) << "\"/>\n  </joint>\n";
    prev = anchor;
    parent = link;
  }
  const Vector3d tool = Vector3d(robot.payload_point_m[0], robot.payload_point_m[1], robot.payload_point_m[2]) - base - prev;
  out << "  <link name=\"tool\"/>\n  <joint name=\"tool_fixed\" type=\"fixed\">\n    <parent link=\"" << parent
      << "\"/>\n    <child link=\"tool\"/>\n    <origin xyz=\"" << tool.x() << " " << tool.y() << " "
      << tool.z() << "\" rpy=\"0 0 0\"/>\n  </joint>\n</robot>\n";
  return out.str();
}

nlohmann::json DrivesJson(const RobotConfig& robot) {
  const nlohmann::json full = RobotToJson(robot);
  const std::vector<JointBody> bodies = WithBodies(robot).bodies;
  nlohmann::json drives = nlohmann::json::object();
  for (size_t i = 0; i < bodies.size(); ++i) drives[bodies[i].joint_name] = full["modules"][i];
  return drives;
}

}  // namespace armfault
