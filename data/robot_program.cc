#include "data/robot_program.h"

#include <cmath>
#include <sstream>

#include "data/error.h"
#include "data/yaml_util.h"

namespace kincal {
namespace {

void CheckRobot(ProgramFormat format, const Robot& robot) {
  const int n = static_cast<int>(robot.joints.size());
  for (const RobotRow& j : robot.joints) {
    if (j.type != JointType::kRevolute) {
      throw InputError("--program: joint " + j.name +
                       " is prismatic; the controller formats here take "
                       "revolute arms only (use the joint CSV)");
    }
  }
  const char* name = format == ProgramFormat::kUrscript ? "URScript"
                     : format == ProgramFormat::kKrl    ? "KRL"
                     : format == ProgramFormat::kRapid  ? "RAPID"
                                                        : "Franka";
  const bool ok = format == ProgramFormat::kUrscript ? n == 6
                  : format == ProgramFormat::kFranka ? n == 7
                                                     : n >= 1 && n <= 12;
  if (!ok) {
    throw InputError(std::string("--program ") + name + ": the robot has " +
                     std::to_string(n) + " joints; the format takes " +
                     (format == ProgramFormat::kUrscript ? "6"
                      : format == ProgramFormat::kFranka ? "7"
                                                         : "1..12") +
                     " (use the joint CSV)");
  }
}

void Header(std::ostringstream& os, const char* prefix,
            const std::vector<std::string>& comment) {
  for (const std::string& c : comment) os << prefix << " " << c << "\n";
  os << prefix
     << " Not run on a real controller: check speeds and the path with a slow "
        "dry run first.\n";
}

std::string Urscript(const std::vector<std::string>& ids,
                     const std::vector<std::vector<double>>& rows,
                     const std::vector<std::string>& comment) {
  std::ostringstream os;
  Header(os, "#", comment);
  os << "def kincal_compensated():\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    os << "  # " << ids[i] << "\n  movej([";
    for (size_t j = 0; j < rows[i].size(); ++j) {
      os << (j ? ", " : "") << FormatFixed(rows[i][j] * M_PI / 180.0, 9);
    }
    os << "], a=0.5, v=0.2)\n";
  }
  os << "end\n";
  return os.str();
}

std::string Krl(const std::vector<std::string>& ids,
                const std::vector<std::vector<double>>& rows,
                const std::vector<std::string>& comment) {
  std::ostringstream os;
  Header(os, ";", comment);
  os << "DEF kincal_compensated()\n  DECL E6AXIS POSES[" << rows.size()
     << "]\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    os << "  POSES[" << i + 1 << "] = {";
    for (size_t j = 0; j < rows[i].size(); ++j) {
      const std::string axis =
          j < 6 ? "A" + std::to_string(j + 1) : "E" + std::to_string(j - 5);
      os << (j ? ", " : "") << axis << " " << FormatFixed(rows[i][j], 6);
    }
    os << "}  ; " << ids[i] << "\n";
  }
  os << "  FOR I = 1 TO " << rows.size()
     << "\n    PTP POSES[I]\n  ENDFOR\nEND\n";
  return os.str();
}

std::string Rapid(const std::vector<std::string>& ids,
                  const std::vector<std::vector<double>>& rows,
                  const std::vector<std::string>& comment) {
  std::ostringstream os;
  Header(os, "!", comment);
  os << "MODULE KincalCompensated\n  CONST jointtarget poses{" << rows.size()
     << "} := [\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    std::string rax, eax;
    for (size_t j = 0; j < 6; ++j) {
      rax += (j ? "," : "") + (j < rows[i].size() ? FormatFixed(rows[i][j], 6)
                                                  : std::string("0"));
    }
    for (size_t j = 6; j < 12; ++j) {
      eax +=
          (j > 6 ? "," : "") + (j < rows[i].size() ? FormatFixed(rows[i][j], 6)
                                                   : std::string("9E9"));
    }
    os << "    [[" << rax << "],[" << eax << "]]"
       << (i + 1 < rows.size() ? "," : "") << "  ! " << ids[i] << "\n";
  }
  os << "  ];\n  PROC main()\n    FOR i FROM 1 TO Dim(poses, 1) DO\n"
        "      MoveAbsJ poses{i}, v100, fine, tool0;\n    ENDFOR\n"
        "  ENDPROC\nENDMODULE\n";
  return os.str();
}

std::string Franka(const std::vector<std::string>& ids,
                   const std::vector<std::vector<double>>& rows,
                   const std::vector<std::string>& comment) {
  std::ostringstream os;
  Header(os, "//", comment);
  os << "// Joint targets in radians, for libfranka's MotionGenerator:\n"
        "//   for (const auto& q : kPoses) { MotionGenerator m(0.1, q); "
        "robot.control(m); }\n"
        "#include <array>\n\nconst std::array<std::array<double, 7>, "
     << rows.size() << "> kPoses = {{\n";
  for (size_t i = 0; i < rows.size(); ++i) {
    os << "    {{";
    for (size_t j = 0; j < rows[i].size(); ++j) {
      os << (j ? ", " : "") << FormatFixed(rows[i][j] * M_PI / 180.0, 9);
    }
    os << "}},  // " << ids[i] << "\n";
  }
  os << "}};\n";
  return os.str();
}

}  // namespace

ProgramFormat ParseProgramFormat(const std::string& name) {
  if (name == "urscript") return ProgramFormat::kUrscript;
  if (name == "krl") return ProgramFormat::kKrl;
  if (name == "rapid") return ProgramFormat::kRapid;
  if (name == "franka") return ProgramFormat::kFranka;
  throw InputError("--program: unknown format '" + name +
                   "' (expected urscript, krl, rapid or franka)");
}

std::string ProgramExtension(ProgramFormat format) {
  switch (format) {
    case ProgramFormat::kUrscript:
      return ".script";
    case ProgramFormat::kKrl:
      return ".src";
    case ProgramFormat::kRapid:
      return ".mod";
    case ProgramFormat::kFranka:
      return ".cpp";
  }
  return ".txt";
}

std::string FormatJointProgram(ProgramFormat format, const Robot& robot,
                               const std::vector<std::string>& ids,
                               const std::vector<std::vector<double>>& rows,
                               const std::vector<std::string>& comment) {
  CheckRobot(format, robot);
  switch (format) {
    case ProgramFormat::kUrscript:
      return Urscript(ids, rows, comment);
    case ProgramFormat::kKrl:
      return Krl(ids, rows, comment);
    case ProgramFormat::kRapid:
      return Rapid(ids, rows, comment);
    case ProgramFormat::kFranka:
      return Franka(ids, rows, comment);
  }
  return "";
}

}  // namespace kincal
