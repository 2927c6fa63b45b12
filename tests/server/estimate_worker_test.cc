// The Estimate calls' worker threads: a job runs on the worker's own thread, the same one call
// after call, and what it throws reaches the caller.
#include "server/estimate_worker.h"

#include <stdexcept>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

namespace hpose::server {
namespace {

TEST(EstimateWorkerTest, JobsRunOnTheWorkersOwnThreadEveryTime) {
  EstimateWorker worker;
  std::vector<std::thread::id> ran;
  for (int i = 0; i < 5; ++i) worker.Run([&] { ran.push_back(std::this_thread::get_id()); });
  ASSERT_EQ(ran.size(), 5u);  // Run returned after each job had run.
  for (const std::thread::id& id : ran) {
    EXPECT_NE(id, std::this_thread::get_id());
    EXPECT_EQ(id, ran.front());
  }
  // Another worker, another thread.
  EstimateWorker other;
  std::thread::id other_id;
  other.Run([&] { other_id = std::this_thread::get_id(); });
  EXPECT_NE(other_id, ran.front());
}

TEST(EstimateWorkerTest, WhatAJobThrowsReachesTheCallerAndTheWorkerGoesOn) {
  EstimateWorker worker;
  EXPECT_THROW(worker.Run([] { throw std::runtime_error("out of memory"); }), std::runtime_error);
  int ran = 0;
  worker.Run([&] { ++ran; });
  EXPECT_EQ(ran, 1);
}

}  // namespace
}  // namespace hpose::server
