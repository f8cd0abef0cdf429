// core/process: the one way dynbench runs other programs.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <vector>

#include "core/process.h"
#include "gltf_builder.h"

namespace dynbench {
namespace {

TEST(Process, ArgumentsEnvironmentFolderAndLines) {
  const auto dir = test::freshDir("process");
  std::vector<std::string> lines;
  // An argument with spaces and quotes reaches the program as one argument: no shell in between.
  auto run = runProcess({.argv = {"sh", "-c", "printf '%s\\n' \"$1\" \"$DYNBENCH_TEST_VALUE\" \"$(pwd)\"; echo oops >&2; exit 3", "sh",
                                  "two words 'and' \"quotes\""},
                         .environment = {{"DYNBENCH_TEST_VALUE", "from the options"}},
                         .workingDirectory = dir,
                         .onLine = [&](std::string_view line) {
                           lines.emplace_back(line);
                           return true;
                         }});
  ASSERT_TRUE(run) << run.error().message;
  EXPECT_EQ(run->exitStatus, 3);
  EXPECT_FALSE(run->succeeded());
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], "two words 'and' \"quotes\"");
  EXPECT_EQ(lines[1], "from the options");
  EXPECT_EQ(lines[2], dir.string());
  EXPECT_EQ(lines[3], "oops");  // stderr merged into the same stream
  EXPECT_EQ(run->tail, "two words 'and' \"quotes\"\nfrom the options\n" + dir.string() + "\noops");
}

TEST(Process, StopsTheProgramWhenTheCallerSaysSo) {
  int seen = 0;
  auto run = runProcess({.argv = {"sh", "-c", "echo first; exec sleep 30"}, .onLine = [&](std::string_view) {
                           ++seen;
                           return false;
                         }});
  ASSERT_TRUE(run) << run.error().message;
  EXPECT_EQ(seen, 1);
  EXPECT_EQ(run->signal, 15);  // SIGTERM, well before the 30 s sleep ends
  EXPECT_EQ(run->tail, "first");
  EXPECT_TRUE(run->stoppedByCaller);
}

TEST(Process, AProgramThatFinishesButDoesNotExitIsStoppedWhenAskedWhileSilent) {
  // Like the Cube 2 client that has written its capture and then hangs in its own shutdown: the
  // program prints nothing more, so only the periodic question can stop it.
  bool finished = false;
  int asked = 0;
  const auto started = std::chrono::steady_clock::now();
  auto run = runProcess({.argv = {"sh", "-c", "echo done; exec sleep 30"},
                         .onLine = [&](std::string_view line) {
                           finished = finished || line == "done";
                           return true;
                         },
                         .stopIf = [&] { return ++asked >= 3 && finished; }});
  ASSERT_TRUE(run) << run.error().message;
  EXPECT_TRUE(run->stoppedByCaller);
  EXPECT_EQ(run->signal, 15);
  EXPECT_GE(asked, 3);
  // Asked about once a second while silent: stopped after seconds, not after the 30 s sleep.
  EXPECT_LT(std::chrono::steady_clock::now() - started, std::chrono::seconds(20));
  // A program that exits by itself is not marked as stopped.
  auto quick = runProcess({.argv = {"sh", "-c", "echo done"}, .stopIf = [] { return false; }});
  ASSERT_TRUE(quick);
  EXPECT_FALSE(quick->stoppedByCaller);
  EXPECT_EQ(quick->exitStatus, 0);
}

TEST(Process, AProgramThatIsNotThereIsAnError) {
  auto run = runProcess({.argv = {"dynbench-no-such-program"}});
  ASSERT_FALSE(run);
  EXPECT_EQ(run.error().code, ErrorCode::kExternalTool);
  EXPECT_EQ(run.error().message, "cannot run dynbench-no-such-program: No such file or directory");
}

}  // namespace
}  // namespace dynbench
