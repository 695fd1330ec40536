// The parapm command-line tool as a user runs it: real process, real files, exit codes,
// one JSON object with --json, one clear line on stderr for bad input.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "test_support.h"

namespace parapm {
namespace {

namespace fs = std::filesystem;

struct CliRun {
  int status = -1;
  std::string out;
  std::string err;
};

CliRun parapm(const std::string& args) {
  static int counter = 0;
  const fs::path err_file =
      fs::temp_directory_path() /
      ("parapm-cli-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ".err");
  const std::string command =
      std::string(PARAPM_BINARY_DIR) + "/parapm " + args + " 2>" + err_file.string();
  CliRun run;
  FILE* pipe = popen(command.c_str(), "r");
  std::array<char, 4096> buffer;
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) run.out.append(buffer.data(), n);
  const int raw = pclose(pipe);
  run.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  std::ifstream err(err_file);
  run.err.assign(std::istreambuf_iterator<char>(err), {});
  fs::remove(err_file);
  return run;
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("parapm-cli-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

TEST_F(Cli, SimplifyCheckLodInfo) {
  const std::string mesh = testing::test_data("pymeshlab-bunny-textured-10k.obj");
  const std::string pm = path("bunny.pm");
  CliRun r = parapm("simplify " + mesh + " -o " + pm + " --ratio 0.1 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"in_faces\":9999"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"base_faces\":"), std::string::npos);
  EXPECT_NE(r.out.find("\"metric\":\"quadric\""), std::string::npos);
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << "one JSON line";

  r = parapm("check " + pm + " --against " + mesh);
  EXPECT_EQ(r.status, 0) << r.out << r.err;

  r = parapm("lod " + pm + " --faces 2000 -o " + path("lod.obj") + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(path("lod.obj")));
  r = parapm("lod " + pm + " --faces 2000 -o " + path("lod.ply"));
  ASSERT_EQ(r.status, 0) << r.err;

  r = parapm("info " + pm + " --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"full_faces\":9999"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"texcoords\""), std::string::npos) << r.out;
}

TEST_F(Cli, SimplifyWithTheEnergyMetric) {
  const std::string mesh = testing::test_data("stratocaster-9k.ply");
  const std::string pm = path("strat.pm");
  CliRun r = parapm("simplify " + mesh + " -o " + pm +
                    " --metric energy --samples-per-face 1 --seed 3 --ratio 0.1 --json");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("\"metric\":\"energy\""), std::string::npos) << r.out;
  r = parapm("check " + pm + " --against " + mesh);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  r = parapm("info " + pm + " --json");
  EXPECT_NE(r.out.find("\"metric\":\"energy\""), std::string::npos) << r.out;

  r = parapm("simplify " + mesh + " -o " + pm + " --metric hausdorff");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("hausdorff"), std::string::npos) << r.err;
  r = parapm("simplify " + mesh + " -o " + pm + " --metric energy --samples-per-face -1");
  EXPECT_EQ(r.status, 2) << r.err;
}

// The quadric's three placements build three different PMs, each exact at full resolution;
// an unknown one is refused by name.
TEST_F(Cli, TheQuadricPlacementIsTheUsers) {
  const std::string mesh = testing::test_data("gmsh-aneurysm-20k.stl.gz");
  std::vector<std::string> bytes;
  for (const std::string placement : {"auto", "constrained", "free"}) {
    const std::string pm = path(placement + ".pm");
    CliRun r =
        parapm("simplify " + mesh + " -o " + pm + " --ratio 0.02 --quadric-placement " + placement);
    ASSERT_EQ(r.status, 0) << placement << ": " << r.err;
    r = parapm("check " + pm + " --against " + mesh);
    EXPECT_EQ(r.status, 0) << placement << ": " << r.out << r.err;
    std::ifstream in(pm, std::ios::binary);
    bytes.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  EXPECT_NE(bytes[0], bytes[1]) << "auto places freely at the fine levels";
  EXPECT_NE(bytes[0], bytes[2]) << "auto keeps volume and border at the coarse levels";
  EXPECT_NE(bytes[1], bytes[2]);
  const CliRun r =
      parapm("simplify " + mesh + " -o " + path("x.pm") + " --quadric-placement loose");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("loose"), std::string::npos) << r.err;
}

TEST_F(Cli, CheckFailsAgainstAnotherMesh) {
  const std::string pm = path("strat.pm");
  ASSERT_EQ(parapm("simplify " + testing::test_data("stratocaster-9k.ply") + " -o " + pm).status,
            0);
  const CliRun r =
      parapm("check " + pm + " --against " + testing::test_data("cad-featuretype-3k.stl"));
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("DIFFERENT"), std::string::npos) << r.out;
}

TEST_F(Cli, BadInputGivesOneClearLine) {
  std::ofstream(path("garbage.ply")) << "ply\nformat ascii 1.0\nelement vertex 1000000000000\n"
                                        "property float x\nend_header\n1 2 3\n";
  CliRun r = parapm("simplify " + path("garbage.ply") + " -o " + path("x.pm"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("garbage.ply"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(path("x.pm")));

  std::ofstream(path("not-a-pm.pm")) << "hello";
  r = parapm("info " + path("not-a-pm.pm"));
  EXPECT_EQ(r.status, 2);
  EXPECT_FALSE(r.err.empty());

  r = parapm("simplify " + path("missing.obj") + " -o " + path("x.pm"));
  EXPECT_EQ(r.status, 2);
  r = parapm("lod " + path("not-a-pm.pm") + " -o " + path("y.obj"));
  EXPECT_EQ(r.status, 2) << "--faces or --error is required";
}

TEST_F(Cli, PartitionReportsTheThesisMetrics) {
  const std::string mesh = testing::test_data("cad-cycloidal-43k.ply");
  CliRun r = parapm("partition " + mesh + " -p 4 --json -o " + path("parts.ply"));
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* field : {"\"p\":4", "\"algo\":\"greedy\"", "\"subset_faces\":",
                            "\"stddev_faces\":", "\"biggest_faces\":", "\"ideal_faces\":",
                            "\"cut_faces\":", "\"cut_edges\":", "\"components\":"})
    EXPECT_NE(r.out.find(field), std::string::npos) << field << " in " << r.out;
  EXPECT_TRUE(fs::exists(path("parts.ply")));
  r = parapm("partition " + mesh + " -p 3 --weights 1,2");
  EXPECT_EQ(r.status, 2) << "three subsets need three weights";
  EXPECT_FALSE(r.err.empty());
}

TEST_F(Cli, HelpTellsTheCommands) {
  const CliRun r = parapm("--help");
  EXPECT_EQ(r.status, 0);
  for (const char* command : {"simplify", "lod", "info", "check", "partition"})
    EXPECT_NE(r.out.find(command), std::string::npos) << command;
}

}  // namespace
}  // namespace parapm
