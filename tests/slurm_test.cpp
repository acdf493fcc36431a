// The Slurm scripts end to end: brings up a real single-node Slurm on this machine
// (munged, slurmctld and slurmd with their own key, configuration, ports and files in a temporary
// folder), submits a 4-shard render and its dependent merge through scripts/slurm/submit.sh, and
// compares the merged images with one `pxf render` of the same settings. Where Slurm cannot be
// brought up (binaries missing, a daemon fails, the node never becomes idle) the test is skipped
// with the reason; it never waits unboundedly, and it stops every process it started, including
// job processes, whatever happens.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <pwd.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <thread>

#include "image/image.h"
#include "tests/test_support.h"

namespace fs = std::filesystem;
using namespace pxf;
using Clock = std::chrono::steady_clock;

namespace {

std::string slurp(const fs::path& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string tail(const fs::path& path, size_t chars = 1500) {
  const std::string text = slurp(path);
  return "--- " + path.filename().string() + ":\n" + (text.size() > chars ? text.substr(text.size() - chars) : text);
}

// Runs a shell command: its exit code and its stdout and stderr together.
struct Output {
  int code = -1;
  std::string text;
};
Output shell(const std::string& cmd) {
  Output out;
  FILE* pipe = ::popen((cmd + " 2>&1").c_str(), "r");
  if (!pipe) return out;
  char buffer[4096];
  for (size_t n; (n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0;) out.text.append(buffer, n);
  const int status = ::pclose(pipe);
  out.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}

std::string quote(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

// The executable `name` on PATH or in /usr/sbin, /usr/bin (root's daemons), or "".
std::string find_program(const std::string& name) {
  std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  path += ":/usr/sbin:/usr/bin:/usr/local/sbin:/usr/local/bin";
  std::istringstream dirs(path);
  for (std::string dir; std::getline(dirs, dir, ':');)
    if (!dir.empty() && ::access((dir + "/" + name).c_str(), X_OK) == 0) return dir + "/" + name;
  return "";
}

// A TCP port free on 127.0.0.1 just now (the kernel's choice), or 0.
int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return 0;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof addr;
  int port = 0;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0 &&
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) == 0)
    port = ntohs(addr.sin_port);
  ::close(fd);
  return port;
}

bool wait_until(double seconds, const std::function<bool()>& done, double poll = 0.25) {
  const auto end = Clock::now() + std::chrono::duration<double>(seconds);
  for (;;) {
    if (done()) return true;
    if (Clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::duration<double>(poll));
  }
}

// munged, slurmctld and slurmd of one test, all in the foreground as children of this process,
// every file of theirs in `dir`. The destructor cancels the jobs, shuts the daemons down (SIGKILL
// after a bounded wait), kills whatever still carries this cluster's marker in its environment
// (job steps, which slurmd detaches) and removes `dir`.
class Cluster {
 public:
  Cluster() {
    char name[] = "/tmp/pxf-slurm-XXXXXX";  // short: the munge socket path must fit sun_path
    if (::mkdtemp(name)) dir_ = name;
  }
  Cluster(const Cluster&) = delete;
  Cluster& operator=(const Cluster&) = delete;
  ~Cluster() {
    stop();
    if (!dir_.empty()) {
      std::error_code ec;
      fs::remove_all(dir_, ec);
    }
  }

  const std::string& dir() const { return dir_; }

  // The environment prefix of every Slurm command of this cluster.
  std::string env() const { return "env SLURM_CONF=" + quote(conf_) + " PXF_SLURM_TEST_DIR=" + quote(dir_) + " "; }

  // Runs a Slurm client command of this cluster, at most `seconds`.
  Output client(const std::string& args, int seconds = 15) const {
    return shell(env() + "timeout -k 2 " + std::to_string(seconds) + " " + args);
  }

  // Starts everything; "" when the node is idle, else why it could not be brought up.
  std::string start() {
    if (dir_.empty()) return "cannot create a temporary folder";
    for (const char* p : {"munged", "mungekey", "slurmctld", "slurmd", "sbatch", "sinfo", "squeue", "scontrol",
                          "scancel", "timeout"})
      if (find_program(p).empty()) return std::string(p) + " not found (apt-get install slurm-wlm munge)";
    if (::chmod(dir_.c_str(), 0755) != 0) return "chmod of " + dir_ + " failed";  // munged: socket dir x for all

    // munge with its own key and socket.
    const std::string key = dir_ + "/munge.key", socket = dir_ + "/munge.sock";
    if (shell(find_program("mungekey") + " -c -k " + quote(key)).code != 0 || ::chmod(key.c_str(), 0400) != 0)
      return "mungekey could not create a key";
    munged_ = spawn({find_program("munged"), "-F", "--key-file=" + key, "--socket=" + socket,
                     "--pid-file=" + dir_ + "/munged.pid", "--log-file=" + dir_ + "/munged.log",
                     "--seed-file=" + dir_ + "/munged.seed"},
                    "munged.out");
    if (!wait_until(10, [&] { return fs::exists(socket) || !alive(munged_); }) || !alive(munged_))
      return "munged did not start\n" + tail(dir_ + "/munged.out");

    // slurm.conf: one node (this host, CPUs=2) on 127.0.0.1, ports chosen by the kernel.
    char host[256] = {};
    ::gethostname(host, sizeof host - 1);
    std::string node = host;
    node = node.substr(0, node.find('.'));
    const int ctld_port = free_port(), slurmd_port = free_port();
    if (node.empty() || ctld_port == 0 || slurmd_port == 0 || ctld_port == slurmd_port)
      return "no host name or no free port";
    fs::create_directories(dir_ + "/state");
    fs::create_directories(dir_ + "/spool");
    std::ofstream(dir_ + "/plugstack.conf").flush();
    conf_ = dir_ + "/slurm.conf";
    std::ofstream conf(conf_);
    conf << "ClusterName=pxftest\n"
         << "SlurmctldHost=" << node << "(127.0.0.1)\n"
         << "SlurmctldPort=" << ctld_port << "\nSlurmdPort=" << slurmd_port << "\n"
         << "SlurmUser=root\nSlurmdUser=root\n"
         << "AuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket=" << socket << "\n"
         << "StateSaveLocation=" << dir_ << "/state\nSlurmdSpoolDir=" << dir_ << "/spool\n"
         << "SlurmctldPidFile=" << dir_ << "/slurmctld.pid\nSlurmdPidFile=" << dir_ << "/slurmd.pid\n"
         << "SlurmctldLogFile=" << dir_ << "/slurmctld.log\nSlurmdLogFile=" << dir_ << "/slurmd.log\n"
         << "PlugStackConfig=" << dir_ << "/plugstack.conf\n"
         << "ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\nJobAcctGatherType=jobacct_gather/none\n"
         << "AccountingStorageType=accounting_storage/none\nJobCompType=jobcomp/none\n"
         << "MpiDefault=none\nSwitchType=switch/none\nMailProg=/bin/true\n"
         << "SelectType=select/cons_tres\nSelectTypeParameters=CR_CPU\nSchedulerType=sched/builtin\n"
         << "ReturnToService=2\nSlurmdParameters=config_overrides\n"
         << "NodeName=" << node << " NodeAddr=127.0.0.1 CPUs=2 RealMemory=100 State=UNKNOWN\n"
         << "PartitionName=pxf Nodes=" << node << " Default=YES MaxTime=INFINITE State=UP\n";
    conf.close();
    if (!conf) return "cannot write " + conf_;

    ctld_ = spawn({find_program("slurmctld"), "-D", "-i", "-f", conf_}, "slurmctld.out");
    slurmd_ = spawn({find_program("slurmd"), "-D", "-f", conf_, "-N", node}, "slurmd.out");
    std::string state;
    const bool idle = wait_until(30, [&] {
      if (!alive(ctld_) || !alive(slurmd_)) return true;
      state = client("sinfo -h -N -o %T", 5).text;
      return state.find("idle") == 0;
    });
    const std::string logs = tail(dir_ + "/slurmctld.out") + "\n" + tail(dir_ + "/slurmctld.log") + "\n" +
                             tail(dir_ + "/slurmd.out") + "\n" + tail(dir_ + "/slurmd.log");
    if (!alive(ctld_)) return "slurmctld exited\n" + logs;
    if (!alive(slurmd_)) return "slurmd exited\n" + logs;
    if (!idle) return "the node did not become idle within 30 s (sinfo: " + state + ")\n" + logs;
    return "";
  }

  void stop() {
    if (alive(ctld_)) {
      const std::string user = ::getpwuid(::getuid()) ? ::getpwuid(::getuid())->pw_name : "root";
      client("scancel -u " + user, 10);
      wait_until(15, [&] { return client("squeue -h -o %i", 5).text.empty(); }, 0.5);
      client("scontrol shutdown", 10);
    }
    end(ctld_, 10);
    end(slurmd_, 10);
    end(munged_, 5);
    kill_marked();
  }

 private:
  // Starts argv in the foreground, in its own process group, output to dir/log.
  pid_t spawn(const std::vector<std::string>& argv, const std::string& log) {
    const std::string log_path = dir_ + "/" + log;
    const pid_t pid = ::fork();
    if (pid == 0) {
      ::setpgid(0, 0);
      ::setenv("PXF_SLURM_TEST_DIR", dir_.c_str(), 1);
      if (!conf_.empty()) ::setenv("SLURM_CONF", conf_.c_str(), 1);
      if (!std::freopen(log_path.c_str(), "w", stdout)) ::_exit(126);
      ::dup2(::fileno(stdout), 2);
      std::vector<char*> args;
      for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
      args.push_back(nullptr);
      ::execv(args[0], args.data());
      ::_exit(127);
    }
    return pid;
  }

  static bool alive(pid_t pid) {
    if (pid <= 0) return false;
    int status = 0;
    return ::waitpid(pid, &status, WNOHANG) == 0;
  }

  // SIGTERM unless already exiting, at most `seconds` for it to end, then SIGKILL; reaps it.
  static void end(pid_t& pid, double seconds) {
    if (pid <= 0) return;
    if (alive(pid)) {
      if (!wait_until(1, [&] { return !alive(pid); }, 0.1)) {
        ::kill(pid, SIGTERM);
        if (!wait_until(seconds, [&] { return !alive(pid); }, 0.1)) ::kill(-pid, SIGKILL), ::kill(pid, SIGKILL);
      }
      ::waitpid(pid, nullptr, 0);
    }
    ::kill(-pid, SIGKILL);  // anything left in its process group
    pid = -1;
  }

  // SIGKILLs every process whose environment names this cluster (job steps and their pxf).
  void kill_marked() const {
    if (dir_.empty()) return;
    const std::string marker = "PXF_SLURM_TEST_DIR=" + dir_;
    for (int round = 0; round < 3; ++round) {
      bool found = false;
      std::error_code ec;
      for (const fs::directory_entry& entry : fs::directory_iterator("/proc", ec)) {
        const std::string name = entry.path().filename().string();
        if (name.find_first_not_of("0123456789") != std::string::npos) continue;
        const pid_t pid = std::stoi(name);
        if (pid == ::getpid()) continue;
        std::istringstream vars(slurp(entry.path() / "environ"));
        for (std::string var; std::getline(vars, var, '\0');)
          if (var == marker) {
            ::kill(pid, SIGKILL);
            found = true;
            break;
          }
      }
      if (!found) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
  }

  std::string dir_, conf_;
  pid_t munged_ = -1, ctld_ = -1, slurmd_ = -1;
};

using test_support::expect_merge_close;

}  // namespace

TEST(Slurm, ShardArrayAndDependentMergeEqualOneRender) {
  const auto started = Clock::now();
  Cluster cluster;
  if (const std::string why = cluster.start(); !why.empty()) GTEST_SKIP() << "no local Slurm: " << why;
  const std::string settings = "--scene cornell --size 32x32";
  const std::string out = cluster.dir() + "/out";

  // The 4 shards and the merge, through the script a user runs.
  const std::string submit = std::string(PXF_SOURCE_DIR) + "/scripts/slurm/submit.sh";
  const Output submitted = shell(cluster.env() + "PXF=" + quote(PXF_EXECUTABLE) + " timeout -k 2 30 bash " +
                                 quote(submit) + " 4 " + quote(out) + " 8 " + settings);
  ASSERT_EQ(submitted.code, 0) << submitted.text;
  unsigned array = 0, merge = 0;
  ASSERT_EQ(std::sscanf(submitted.text.c_str(), "shards: job %u (array 0-3), merge: job %u", &array, &merge), 2)
      << submitted.text;

  // The single-machine reference meanwhile.
  const std::string ref = cluster.dir() + "/single";
  const Output single = shell(quote(PXF_EXECUTABLE) + " render " + settings + " --spp 8 --quiet --out " + quote(ref));
  ASSERT_EQ(single.code, 0) << single.text;

  // Every job done (or 120 s): squeue -t all lists finished jobs for MinJobAge (300 s).
  const std::string jobs = std::to_string(array) + "," + std::to_string(merge);
  std::string states;
  const bool finished = wait_until(120, [&] {
    states = cluster.client("squeue -h -t all -j " + jobs + " -o '%i %T %r'", 10).text;
    if (states.find("DependencyNeverSatisfied") != std::string::npos) return true;  // a shard failed
    for (const char* active : {"PENDING", "CONFIGURING", "RUNNING", "COMPLETING", "REQUEUE", "RESIZING", "SUSPENDED"})
      if (states.find(active) != std::string::npos) return false;
    return !states.empty();
  }, 0.5);
  std::string logs;
  for (const fs::directory_entry& e : fs::directory_iterator(out))
    if (e.path().extension() == ".log") logs += tail(e.path(), 600) + "\n";
  if (!finished && states.find("RUNNING") == std::string::npos && states.find("COMPLETED") == std::string::npos &&
      states.find("FAILED") == std::string::npos)
    GTEST_SKIP() << "Slurm did not start the jobs within 120 s:\n" << states << tail(cluster.dir() + "/slurmctld.log");
  ASSERT_TRUE(finished) << "jobs not done within 120 s:\n" << states << logs;
  EXPECT_EQ(states.find("FAILED"), std::string::npos) << states << logs;
  EXPECT_EQ(states.find("DependencyNeverSatisfied"), std::string::npos) << states << logs;
  ASSERT_TRUE(fs::exists(out + "/merged/final.exr")) << states << logs;
  for (int i = 0; i < 4; ++i) EXPECT_TRUE(fs::exists(out + "/shard-" + std::to_string(i) + "/state.pxfs")) << i;

  const std::vector<Layer> merged = read_exr_layers(out + "/merged/buffers.exr");
  const std::vector<Layer> reference = read_exr_layers(ref + "/buffers.exr");
  for (const char* name : {"lv", "hv", "var_u", "samples", "final"})
    expect_merge_close(layer_image(merged, name), layer_image(reference, name), std::string("buffers.exr ") + name);
  expect_merge_close(read_exr(out + "/merged/final.exr"), read_exr(ref + "/final.exr"), "final.exr");
  std::printf("[ slurm    ] jobs done in %.1f s\n", std::chrono::duration<double>(Clock::now() - started).count());
}
