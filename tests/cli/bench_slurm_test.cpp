// End-to-end on a real (one-node, local) Slurm: bench/slurm/local_slurm.sh starts slurmctld and
// slurmd in a temporary folder on 127.0.0.1 (AuthType=auth/none, no munge), bench/slurm/submit.sh
// submits a 4-shard sweep as a job array plus the job that combines it, and the combined results
// must equal the same sweep run locally. The daemons are stopped by their process ids when the test
// ends, and by a watchdog if the test process dies first.
#include <gtest/gtest.h>
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdlib>

#include "tests/cli/bench_test_support.h"

namespace fleetmap::cli {
namespace {

using namespace fleetmap::testing;

struct ShellResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

ShellResult run_shell(const std::string& command, const TempDir& scratch, const std::string& log_name) {
  const auto log = scratch / log_name;
  const std::string cmd = "cd '" + scratch.path().string() + "' && ( " + command + " ) >'" + log.string() + "' 2>&1 </dev/null";
  const int status = std::system(cmd.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), slurp(log)};
}

// A TCP port on 127.0.0.1 that nothing listens on now.
int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = 0;
  socklen_t len = sizeof a;
  int port = -1;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 && ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0) {
    port = ntohs(a.sin_port);
  }
  ::close(fd);
  return port;
}

std::string all_logs(const std::filesystem::path& dir) {
  std::string text;
  if (!std::filesystem::exists(dir)) return text;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    if (e.path().extension() != ".log" && e.path().extension() != ".out") continue;
    std::string body = slurp(e.path());
    if (body.size() > 3000) body = "..." + body.substr(body.size() - 3000);
    text += "---- " + e.path().string() + "\n" + body + "\n";
  }
  return text;
}

// Stops the local cluster when the test ends, however it ends.
class LocalSlurm {
 public:
  LocalSlurm(const TempDir& scratch, std::filesystem::path dir) : scratch_(scratch), dir_(std::move(dir)) {}
  ~LocalSlurm() { run_shell(script() + " stop '" + dir_.string() + "'", scratch_, "slurm_stop.txt"); }
  LocalSlurm(const LocalSlurm&) = delete;
  LocalSlurm& operator=(const LocalSlurm&) = delete;

  ShellResult start(int ctld_port, int slurmd_port) const {
    return run_shell("timeout 150 " + script() + " start '" + dir_.string() + "' " + std::to_string(ctld_port) + " " +
                         std::to_string(slurmd_port) + " " + std::to_string(::getpid()),
                     scratch_, "slurm_start.txt");
  }
  std::string conf() const { return (dir_ / "slurm.conf").string(); }

 private:
  static std::string script() { return std::string("bash '") + FLEETMAP_SOURCE_DIR + "/bench/slurm/local_slurm.sh'"; }
  const TempDir& scratch_;
  std::filesystem::path dir_;
};

TEST(BenchSlurm, FourShardJobArrayEqualsTheLocalRun) {
  TempDir dir;
  write_bench_maps(dir);
  const std::string sweep = "--maps '" + (dir / "room.yaml").string() + "','" + (dir / "hall.yaml").string() +
                            "' --strategies uncoordinated,coordinated --robots 1,2 --seeds 2 --steps 300";

  const int ctld_port = free_port(), slurmd_port = free_port();
  ASSERT_GT(ctld_port, 0);
  ASSERT_GT(slurmd_port, 0);
  ASSERT_NE(ctld_port, slurmd_port);
  LocalSlurm slurm(dir, dir / "slurm");
  const ShellResult started = slurm.start(ctld_port, slurmd_port);
  // local_slurm.sh exits 3 when slurm-wlm is not installed, 1 when the daemons do not come up here
  // (e.g. in a container that forbids them): both are the environment, not fleetmap.
  if (started.exit_code == 3) GTEST_SKIP() << "Slurm is not installed (Debian's slurm-wlm; scripts/install-deps.sh installs it)";
  if (started.exit_code == 1) {
    GTEST_SKIP() << "slurmctld/slurmd could not start on this machine:\n" << started.output;
  }
  ASSERT_EQ(started.exit_code, 0) << started.output << all_logs(dir / "slurm" / "log");

  // sbatch --wait returns when the combine job has ended; a shard that fails cancels it.
  const ShellResult submitted = run_shell(
      "export SLURM_CONF='" + slurm.conf() + "' FLEETMAP='" + FLEETMAP_BINARY +
          "' FLEETMAP_SBATCH_ARGS='--cpus-per-task=1 --time=15'; timeout 240 bash '" + FLEETMAP_SOURCE_DIR +
          "/bench/slurm/submit.sh' --wait 4 cluster " + sweep,
      dir, "submit.txt");
  ASSERT_EQ(submitted.exit_code, 0) << "sbatch of the 4-shard sweep failed:\n"
                                    << submitted.output << all_logs(dir / "cluster" / "logs") << all_logs(dir / "slurm" / "log");
  EXPECT_NE(submitted.output.find("shards: job"), std::string::npos) << submitted.output;

  // Each array task ran its own shard.
  int rows = 0;
  for (int k = 1; k <= 4; ++k) {
    const auto results = dir / "cluster" / ("shard_" + std::to_string(k)) / "results.csv";
    ASSERT_TRUE(std::filesystem::exists(results)) << results << "\n" << all_logs(dir / "cluster" / "logs");
    rows += int(rows_without_wall_time(results).size()) - 1;
  }
  EXPECT_EQ(rows, 16);

  const CliResult local = run_fleetmap("bench " + sweep + " --jobs 2 --out local", dir);
  ASSERT_EQ(local.exit_code, 0) << local.err;
  const auto combined = dir / "cluster" / "all";
  ASSERT_TRUE(std::filesystem::exists(combined / "results.csv")) << all_logs(dir / "cluster" / "logs");
  EXPECT_EQ(rows_without_wall_time(combined / "results.csv"), rows_without_wall_time(dir / "local" / "results.csv"));
  EXPECT_EQ(slurp(combined / "summary.csv"), slurp(dir / "local" / "summary.csv"));
  EXPECT_EQ(slurp(combined / "summary.md"), slurp(dir / "local" / "summary.md"));
  EXPECT_TRUE(std::filesystem::exists(combined / "efficiency.png"));
}

}  // namespace
}  // namespace fleetmap::cli
