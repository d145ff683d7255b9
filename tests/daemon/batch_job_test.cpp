// The pure parts of daemon/batch_job.h: Slurm's task states as squeue and sacct print them, and
// the plan file read back (a piece outside its session is refused, naming the file).
#include "fieldrig/daemon/batch_job.h"

#include <gtest/gtest.h>

namespace fieldrig::daemon {
namespace {

TEST(SlurmTaskStates, SqueueRunningTasksAndPendingRangesAreExpanded) {
  const auto states = parseSlurmTaskStates(
      "17_0 RUNNING\n"
      "17_[2-3%2] PENDING\n"
      "18 RUNNING\n"  // not an array job: not ours to read
      "19_[1,4] PENDING\n");
  ASSERT_EQ(states.size(), 5U);
  EXPECT_EQ(states[0].job_id, "17");
  EXPECT_EQ(states[0].task, 0U);
  EXPECT_EQ(states[0].state, "RUNNING");
  EXPECT_EQ(states[1].task, 2U);
  EXPECT_EQ(states[2].task, 3U);
  EXPECT_EQ(states[2].state, "PENDING");
  EXPECT_EQ(states[3].job_id, "19");
  EXPECT_EQ(states[3].task, 1U);
  EXPECT_EQ(states[4].task, 4U);
}

TEST(SlurmTaskStates, SacctPipeSeparatedLinesKeepTheFirstWordOfTheState) {
  const auto states = parseSlurmTaskStates("21_1|CANCELLED by 0\n21_2|COMPLETED\n21_3|TIMEOUT\n");
  ASSERT_EQ(states.size(), 3U);
  EXPECT_EQ(states[0].state, "CANCELLED");
  EXPECT_FALSE(slurmStateActive(states[0].state));
  EXPECT_FALSE(slurmStateActive("COMPLETED"));
  EXPECT_TRUE(slurmStateActive("RUNNING"));
  EXPECT_TRUE(slurmStateActive("PENDING"));
  EXPECT_TRUE(slurmStateActive("COMPLETING"));
}

TEST(BatchPlanFile, RoundTripsAndRefusesAPieceOutsideItsSession) {
  BatchPlan plan;
  plan.software_version = "0.1.0";
  plan.fieldrig_binary = "/usr/bin/fieldrig";
  plan.parameter_hash = "abc";
  plan.sessions.push_back(
      {"/data/day1", "day1", {5, 6, 7}, {"p1", "p2", "p3"}, "/data/day1/calib"});
  plan.tasks = {{{0, 0, 2}}, {{0, 2, 1}}};
  auto back = batchPlanFromJson(batchPlanToJson(plan), "plan.json");
  ASSERT_TRUE(back) << back.error().message;
  EXPECT_EQ(batchPlanToJson(*back), batchPlanToJson(plan));
  EXPECT_EQ(back->totalSets(), 3U);
  EXPECT_EQ(back->taskSets(0), 2U);

  auto json = batchPlanToJson(plan);
  json["tasks"][1][0]["count"] = 2;  // positions 2 and 3 of a 3-set session
  auto refused = batchPlanFromJson(json, "job/plan.json");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("job/plan.json"), std::string::npos);

  // A plan of a later format, and one whose sbatch option would add a line to the job script.
  json = batchPlanToJson(plan);
  json["format_version"] = 99;
  refused = batchPlanFromJson(json, "job/plan.json");
  ASSERT_FALSE(refused);
  EXPECT_EQ(refused.error().message,
            "job/plan.json: format_version 99, but this fieldrig reads plans of format 1");
  json = batchPlanToJson(plan);
  json["sbatch_options"] = {"--time=1\nrm -rf /"};
  refused = batchPlanFromJson(json, "job/plan.json");
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().message.find("job/plan.json: --sbatch-option"), std::string::npos)
      << refused.error().message;
}

}  // namespace
}  // namespace fieldrig::daemon
