#include <gtest/gtest.h>
#include <omp.h>

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "sonarbench/sim/report/report_page.hpp"

namespace sonarbench::sim {
namespace {

// Each task runs once, whatever the threads, and on two threads two of them run at once.
TEST(RunTasks, RunsEachTaskOnceOnAnyThreadCount) {
  for (const int threads : {1, 2, 0}) {
    std::vector<int> runs(7, 0);
    std::vector<int> thread_of(7, -1);
    std::vector<std::function<void()>> tasks;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      tasks.emplace_back([&, i] {
        ++runs[i];
        thread_of[i] = omp_get_thread_num();
      });
    }
    RunTasks(threads, tasks);
    EXPECT_EQ(runs, std::vector<int>(7, 1)) << threads << " threads";
    if (threads == 1) {
      EXPECT_EQ(thread_of, std::vector<int>(7, 0));
    }
  }
  // Two tasks that each wait for the other finish only if they run side by side.
  int arrived = 0;
  auto meet = [&arrived] {
    int seen = 0;
#pragma omp atomic capture
    seen = ++arrived;
    while (seen < 2) {
#pragma omp atomic read
      seen = arrived;
    }
  };
  const std::function<void()> pair[] = {meet, meet};
  RunTasks(2, pair);
  EXPECT_EQ(arrived, 2);
}

// An exception does not escape a thread: every task still runs, then the first failing task's
// exception (in the tasks' order) is thrown.
TEST(RunTasks, RethrowsTheFirstFailingTasksExceptionAfterAllRan) {
  for (const int threads : {1, 2}) {
    std::vector<int> runs(4, 0);
    const std::function<void()> tasks[] = {[&] { ++runs[0]; },
                                           [&] {
                                             ++runs[1];
                                             throw std::runtime_error("second");
                                           },
                                           [&] {
                                             ++runs[2];
                                             throw std::logic_error("third");
                                           },
                                           [&] { ++runs[3]; }};
    try {
      RunTasks(threads, tasks);
      ADD_FAILURE() << "nothing thrown on " << threads << " threads";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "second");
    }
    EXPECT_EQ(runs, std::vector<int>(4, 1)) << threads << " threads";
  }
}

}  // namespace
}  // namespace sonarbench::sim
