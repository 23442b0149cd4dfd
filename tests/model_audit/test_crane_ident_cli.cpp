// crane_ident end to end: simulate-friction writes a CSV, friction reads it back and prints JSON or a
// table; bad input exits 2 with the reader's message, unidentifiable data exits 3.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#ifndef CRANE_IDENT_EXECUTABLE
#error "CRANE_IDENT_EXECUTABLE must name the crane_ident binary (set by tests/model_audit/CMakeLists.txt)"
#endif

namespace fs = std::filesystem;

namespace {

struct ToolRun {
  int exit_code{-1};
  std::string out;
  std::string err;
};

std::string slurp(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

std::string quote(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

class CraneIdentCli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    directory_ = fs::temp_directory_path() /
                 ("crane_model_audit_cli_" + std::to_string(::getpid()) + "_" + info->name());
    fs::create_directories(directory_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(directory_, ignored);
  }

  ToolRun run(const std::string& arguments) const {
    const fs::path out = directory_ / "stdout.txt";
    const fs::path err = directory_ / "stderr.txt";
    const std::string command = quote(CRANE_IDENT_EXECUTABLE) + " " + arguments + " > " + quote(out.string()) +
                                " 2> " + quote(err.string());
    const int status = std::system(command.c_str());
    ToolRun result;
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    result.out = slurp(out);
    result.err = slurp(err);
    return result;
  }

  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path path = directory_ / name;
    std::ofstream(path) << text;
    return path;
  }

  std::string simulate(const std::string& extra = "") const {
    const fs::path csv = directory_ / "run.csv";
    const auto result = run("simulate-friction --out " + quote(csv.string()) + " " + extra);
    EXPECT_EQ(result.exit_code, 0) << result.err;
    return quote(csv.string());
  }

  fs::path directory_;
};

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_F(CraneIdentCli, SimulateThenIdentifyJson) {
  const std::string csv = simulate();
  const auto result = run("friction --data " + csv + " --axis x --dead-band 0.05 --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto json = nlohmann::json::parse(result.out);
  EXPECT_EQ(json.at("axis"), "x");
  EXPECT_NEAR(json.at("b_plus").get<double>(), 2.8, 0.02 * 2.8);
  EXPECT_NEAR(json.at("b_minus").get<double>(), 5.5, 0.02 * 5.5);
  EXPECT_NEAR(json.at("c_plus").get<double>(), 1.0, 0.02 * 1.0);
  EXPECT_NEAR(json.at("c_minus").get<double>(), 1.2, 0.02 * 1.2);
  EXPECT_NEAR(json.at("K_m").get<double>(), 1.7, 0.02 * 1.7);
  for (const char* key : {"b_plus", "b_minus", "c_plus", "c_minus", "K_m"}) {
    EXPECT_GT(json.at("standard_errors").at(key).get<double>(), 0.0) << key;
  }
  EXPECT_GT(json.at("samples_used").at("positive").get<int>(), 500);
  EXPECT_GT(json.at("samples_used").at("negative").get<int>(), 500);
  EXPECT_EQ(json.at("dead_band").get<double>(), 0.05);
  EXPECT_EQ(json.at("cutoff_hz").get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(json.at("sample_time").get<double>(), 0.01);
}

TEST_F(CraneIdentCli, KnownMotorConstantAndTable) {
  const std::string csv = simulate("--noise 1e-5 --seed 3");
  auto result = run("friction --data " + csv + " --axis x --km 1.7 --cutoff-hz 10 --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  const auto json = nlohmann::json::parse(result.out);
  EXPECT_FALSE(json.contains("K_m"));  // given, not identified
  EXPECT_FALSE(json.at("standard_errors").contains("K_m"));
  EXPECT_EQ(json.at("cutoff_hz").get<double>(), 10.0);
  EXPECT_NEAR(json.at("b_minus").get<double>(), 5.5, 0.02 * 5.5);

  result = run("friction --data " + csv + " --axis x");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_TRUE(contains(result.out, "b+/K_m [V s/m]")) << result.out;
  EXPECT_TRUE(contains(result.out, "K_m [m/s^2/V]")) << result.out;
  EXPECT_TRUE(contains(result.out, "samples used:")) << result.out;
}

TEST_F(CraneIdentCli, GammaAxisAndColumnMapping) {
  // simulate --axis gamma names the position column "gamma", the default for --axis gamma.
  const fs::path csv = directory_ / "slew.csv";
  ASSERT_EQ(run("simulate-friction --axis gamma --out " + quote(csv.string())).exit_code, 0);
  auto result = run("friction --data " + quote(csv.string()) + " --axis gamma --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_EQ(nlohmann::json::parse(result.out).at("axis"), "gamma");
  EXPECT_TRUE(contains(slurp(csv), "t,u,gamma,gamma_true,gamma_rate_true,gamma_ref"));

  // The same data under the truth column names: map the measured position explicitly.
  result = run("friction --data " + quote(csv.string()) + " --axis x --columns 'x=gamma_true' --json");
  ASSERT_EQ(result.exit_code, 0) << result.err;
  EXPECT_NEAR(nlohmann::json::parse(result.out).at("c_minus").get<double>(), 1.2, 0.02 * 1.2);
}

TEST_F(CraneIdentCli, BadDataExitsTwoNamingRowAndColumn) {
  const auto nan_file = write("nan.csv", "# comment\nt,u,x\n0,0,0\n0.01,nan,0\n");
  auto result = run("friction --data " + quote(nan_file.string()) + " --axis x");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_TRUE(contains(result.err, nan_file.string() + ": row 4: column 'u': non-finite value 'nan'")) << result.err;

  const auto missing = write("missing.csv", "time,u,pos\n0,0,0\n0.01,0,0\n0.02,0,0\n");
  result = run("friction --data " + quote(missing.string()) + " --axis gamma");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_TRUE(contains(result.err, "missing required column(s) 't', 'gamma'")) << result.err;
  EXPECT_TRUE(contains(result.err, "columns present: 'time', 'u', 'pos'")) << result.err;

  result = run("friction --data " + quote(missing.string()) + " --axis x --columns 't=time,y=pos'");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_TRUE(contains(result.err, "unknown canonical name 'y'")) << result.err;

  result = run("friction --data " + quote((directory_ / "absent.csv").string()) + " --axis x");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_TRUE(contains(result.err, "cannot open")) << result.err;

  result = run("friction --axis x");  // --data missing
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_TRUE(contains(result.err, "--data")) << result.err;

  result = run("friction --data " + quote(missing.string()) + " --axis x --columns 't=time,x=pos' --dead-band -1");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_TRUE(contains(result.err, "dead_band = -1 is out of range")) << result.err;
}

TEST_F(CraneIdentCli, UnidentifiableDataExitsThree) {
  const std::string csv = simulate();
  const auto result = run("friction --data " + csv + " --axis x --dead-band 5");
  EXPECT_EQ(result.exit_code, 3);
  EXPECT_TRUE(contains(result.err, "too few moving samples")) << result.err;
}
