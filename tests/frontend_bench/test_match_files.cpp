// The matching benchmark's files (frontend_bench/match_files.hpp): what the readers accept, and that every
// bad input names its file and line.
#include <gtest/gtest.h>

#include <fstream>

#include "frontend_bench/match_files.hpp"
#include "io/io_test_support.hpp"

namespace wingman::frontend_bench {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

// The message of the MatchInputError `f` throws ("" if it throws none).
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const MatchInputError& e) {
    return e.what();
  }
  return "";
}

// Two UAVs with frames at 0, 0.1 s and 0.2 s, uav2 3 m from uav1.
datasets::Dataset two_uavs() {
  datasets::Dataset ds;
  ds.root = "/data/ds";
  for (const auto& [name, x] : {std::pair{"uav1", 0.0}, std::pair{"uav2", 3.0}}) {
    datasets::AgentData a;
    a.name = name;
    a.camera = datasets::CameraInfo{};
    for (int k = 0; k < 3; ++k) {
      a.frames.push_back(k * 100'000'000LL);
      datasets::PoseSample p;
      p.t_ns = a.frames.back();
      p.p = {x + 0.4 * k, 0, 15};
      a.camera_pose.push_back(p);
    }
    ds.agents.push_back(a);
  }
  return ds;
}

TEST(MatchFiles, KeypointsAndMatchesRoundTripThroughTheWriters) {
  io::test::TempDir dir;
  const fs::path kf = keypoints_file(dir.path(), "uav1", 100);
  EXPECT_EQ(kf, dir.path() / "keypoints" / "uav1" / "100.csv");
  write_keypoints(kf, {{{1.25, 2.5}, 0.7}, {{-0.5, 99.5}, 0}});
  const auto k = read_keypoints(kf, 100, 100);
  ASSERT_EQ(k.size(), 2u);
  EXPECT_DOUBLE_EQ(k[0].uv.x(), 1.25);
  EXPECT_DOUBLE_EQ(k[1].uv.y(), 99.5);
  EXPECT_DOUBLE_EQ(k[0].score, 0.7);
  write_matches(matches_file(dir.path(), 7), {{1, 0}, {0, 1}});
  const auto m = read_matches(dir.path() / "matches" / "7.csv", 2, 2);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].a, 1);
  EXPECT_EQ(m[1].b, 1);
}

TEST(MatchFiles, HeaderWithoutScoreCommentsAndBlankLinesAreAccepted) {
  io::test::TempDir dir;
  write(dir.path() / "k.csv", "# made by hand\nx,y\n1,2\n\n3.5,4e1\n");
  EXPECT_EQ(read_keypoints(dir.path() / "k.csv", 100, 100).size(), 2u);
  write(dir.path() / "m.csv", "index_a,index_b\r\n0,1\r\n");
  EXPECT_EQ(read_matches(dir.path() / "m.csv", 1, 2).size(), 1u);
}

TEST(MatchFiles, MalformedRowNamesFileAndLine) {
  io::test::TempDir dir;
  write(dir.path() / "k.csv", "x,y\n1,2\n3,abc\n");
  EXPECT_EQ(error_of([&] { read_keypoints(dir.path() / "k.csv", 100, 100); }),
            (dir.path() / "k.csv").string() + ":3: y 'abc' is not a number");
  write(dir.path() / "k2.csv", "x,y\n1,2,3\n");
  EXPECT_EQ(error_of([&] { read_keypoints(dir.path() / "k2.csv", 100, 100); }),
            (dir.path() / "k2.csv").string() + ":2: expected 2 fields, got 3");
  write(dir.path() / "k3.csv", "u,v\n1,2\n");
  EXPECT_NE(error_of([&] { read_keypoints(dir.path() / "k3.csv", 100, 100); }).find("k3.csv:1: header must be 'x,y' or 'x,y,score'"),
            std::string::npos);
  write(dir.path() / "m.csv", "index_a,index_b\n0,1.5\n");
  EXPECT_EQ(error_of([&] { read_matches(dir.path() / "m.csv", 5, 5); }),
            (dir.path() / "m.csv").string() + ":2: index_b '1.5' is not a whole number");
  write(dir.path() / "k4.csv", "x,y\nnan,2\n");
  EXPECT_NE(error_of([&] { read_keypoints(dir.path() / "k4.csv", 100, 100); }).find("k4.csv:2:"), std::string::npos);
}

TEST(MatchFiles, IndexOutOfRangeAndKeypointOutsideImageAreRefused) {
  io::test::TempDir dir;
  write(dir.path() / "m.csv", "index_a,index_b\n0,0\n4,1\n");
  EXPECT_EQ(error_of([&] { read_matches(dir.path() / "m.csv", 4, 2); }),
            (dir.path() / "m.csv").string() + ":3: index_a 4 out of range: frame A has 4 keypoints");
  write(dir.path() / "m2.csv", "index_a,index_b\n0,-1\n");
  EXPECT_EQ(error_of([&] { read_matches(dir.path() / "m2.csv", 4, 2); }),
            (dir.path() / "m2.csv").string() + ":2: index_b -1 out of range: frame B has 2 keypoints");
  write(dir.path() / "k.csv", "x,y\n100,2\n");
  EXPECT_EQ(error_of([&] { read_keypoints(dir.path() / "k.csv", 100, 50); }),
            (dir.path() / "k.csv").string() + ":2: keypoint (100, 2) lies outside the 100 x 50 image");
}

TEST(MatchFiles, MissingOrEmptyFileIsNamed) {
  io::test::TempDir dir;
  EXPECT_EQ(error_of([&] { read_matches(dir.path() / "matches" / "3.csv", 1, 1); }),
            (dir.path() / "matches" / "3.csv").string() + ": missing");
  write(dir.path() / "e.csv", "");
  EXPECT_EQ(error_of([&] { read_keypoints(dir.path() / "e.csv", 10, 10); }),
            (dir.path() / "e.csv").string() + ": empty: a header 'x,y' is needed");
}

TEST(FramePairs, DatasetPairsAreTemporalPerGapThenCrossWithTrueBaselines) {
  const auto ds = two_uavs();
  PairOptions o;
  o.stride = 2;
  o.gaps = {1, 2};
  const auto pairs = make_pairs(ds, o);
  // k = 0: uav1 +1, +2, uav2 +1, +2, cross; k = 2: cross only.
  ASSERT_EQ(pairs.size(), 6u);
  EXPECT_EQ(pairs[1].agent_a, "uav1");
  EXPECT_EQ(pairs[1].t_b, 200'000'000);
  EXPECT_NEAR(pairs[1].baseline_m, 0.8, 1e-12);
  EXPECT_EQ(pairs[4].type, PairType::Cross);
  EXPECT_NEAR(pairs[4].baseline_m, 3.0, 1e-12);
  EXPECT_EQ(pairs[5].id, 5);
  EXPECT_EQ(pairs[5].t_a, 200'000'000);
}

TEST(FramePairs, PairsFileRoundTripsAndAFrameTheDatasetLacksIsNamed) {
  io::test::TempDir dir;
  const auto ds = two_uavs();
  const auto pairs = make_pairs(ds, {});
  write(dir.path() / "pairs.csv", pairs_csv(pairs));
  const auto back = read_pairs(dir.path() / "pairs.csv", ds);
  ASSERT_EQ(back.size(), pairs.size());
  EXPECT_EQ(back.back().agent_b, pairs.back().agent_b);
  EXPECT_NEAR(back[0].baseline_m, pairs[0].baseline_m, 1e-12);
  write(dir.path() / "bad.csv", "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m\n"
                         "0,uav1,0,uav1,100000000,temporal,0.4\n"
                         "1,uav1,0,uav2,50000000,cross,3\n");
  const std::string e = error_of([&] { read_pairs(dir.path() / "bad.csv", ds); });
  EXPECT_NE(e.find((dir.path() / "bad.csv").string() + ":3: names a frame the dataset /data/ds lacks"), std::string::npos) << e;
  EXPECT_NE(e.find("50000000"), std::string::npos) << e;
  write(dir.path() / "dup.csv", "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m\n"
                         "0,uav1,0,uav1,100000000,temporal,0.4\n0,uav1,0,uav1,100000000,temporal,0.4\n");
  EXPECT_NE(error_of([&] { read_pairs(dir.path() / "dup.csv", ds); }).find("dup.csv:3: pair_id 0"), std::string::npos);
}

// two_uavs() again, as rendered under condition `name` into /data/<name>.
Condition condition(const std::string& name) {
  Condition c{name, two_uavs()};
  c.dataset.root = "/data/" + name;
  return c;
}

TEST(FramePairs, ConditionPairsFollowTheReferencesWithSameInstantPairsFirst) {
  const auto ds = two_uavs();
  const Conditions sets(ds, {condition("blur")});
  PairOptions o;
  o.stride = 2;
  o.gaps = {1, 2};
  const auto pairs = make_pairs(sets, o);
  // The reference's 6 (k = 0: 2 UAVs x 2 gaps + cross; k = 2: cross), then blur's: k = 0 per UAV
  // same-instant + 2 gaps, cross; k = 2 per UAV same-instant, cross.
  ASSERT_EQ(pairs.size(), 6u + 7u + 3u);
  EXPECT_EQ(pairs[5].condition, kReference);
  EXPECT_EQ(pairs[6].condition, "blur");
  EXPECT_EQ(pairs[6].type, PairType::SameInstant);
  EXPECT_EQ(pairs[6].t_a, pairs[6].t_b);
  EXPECT_NEAR(pairs[6].baseline_m, 0.0, 1e-12);
  EXPECT_EQ(pairs[7].type, PairType::Temporal);
  EXPECT_NEAR(pairs[7].baseline_m, 0.4, 1e-12);
  EXPECT_EQ(pairs[12].type, PairType::Cross);
  EXPECT_EQ(pairs[13].type, PairType::SameInstant);
  EXPECT_EQ(pairs[15].id, 15);
  const std::string csv = pairs_csv(pairs);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m,condition");
  EXPECT_NE(csv.find("\n6,uav1,0,uav1,0,same-instant,0.0000,blur\n"), std::string::npos) << csv;
  io::test::TempDir dir;
  write(dir.path() / "pairs.csv", csv);
  const auto back = read_pairs(dir.path() / "pairs.csv", sets);
  ASSERT_EQ(back.size(), pairs.size());
  EXPECT_EQ(back[13].condition, "blur");
  EXPECT_EQ(back[13].type, PairType::SameInstant);
  EXPECT_EQ(keypoints_file(dir.path(), "blur", "uav2", 100), dir.path() / "conditions" / "blur" / "keypoints" / "uav2" / "100.csv");
  EXPECT_EQ(keypoints_file(dir.path(), kReference, "uav2", 100), keypoints_file(dir.path(), "uav2", 100));
}

TEST(FramePairs, ASevenColumnPairsFileIsTheReferencesPairs) {
  io::test::TempDir dir;
  const auto ds = two_uavs();
  write(dir.path() / "old.csv", "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m\n"
                                "0,uav1,0,uav1,200000000,temporal,0\n3,uav1,100000000,uav2,100000000,cross,0\n");
  const auto pairs = read_pairs(dir.path() / "old.csv", Conditions(ds, {condition("blur")}));
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].condition, kReference);
  EXPECT_EQ(pairs[1].condition, kReference);
  EXPECT_EQ(pairs[1].id, 3);
  EXPECT_NEAR(pairs[0].baseline_m, 0.8, 1e-12);
  EXPECT_NEAR(pairs[1].baseline_m, 3.0, 1e-12);
}

TEST(FramePairs, AnUnknownConditionOrAReferenceSameInstantPairIsNamedWithFileAndLine) {
  io::test::TempDir dir;
  const auto ds = two_uavs();
  const Conditions sets(ds, {condition("blur")});
  const std::string header = "pair_id,agent_a,t_ns_a,agent_b,t_ns_b,type,baseline_m,condition\n";
  write(dir.path() / "p.csv", header + "0,uav1,0,uav1,0,same-instant,0,blur\n1,uav1,0,uav1,0,same-instant,0,fog\n");
  EXPECT_EQ(error_of([&] { read_pairs(dir.path() / "p.csv", sets); }),
            (dir.path() / "p.csv").string() + ":3: condition 'fog' is none of the datasets given (reference, blur; "
                                              "a condition is given as --condition NAME=DIR)");
  write(dir.path() / "q.csv", header + "0,uav1,0,uav1,0,same-instant,0,reference\n");
  EXPECT_NE(error_of([&] { read_pairs(dir.path() / "q.csv", sets); }).find("q.csv:2: a same-instant pair is one UAV's"),
            std::string::npos);
  write(dir.path() / "r.csv", header + "0,uav1,0,uav1,0,sideways,0,blur\n");
  EXPECT_NE(error_of([&] { read_pairs(dir.path() / "r.csv", sets); }).find("r.csv:2: type must be temporal, cross or same-instant"),
            std::string::npos);
}

TEST(Conditions, AConditionWhosePosesOrFramesDifferIsNamedWithFileAndLine) {
  const auto ds = two_uavs();
  auto dataset_error = [&](const Condition& c) {
    try {
      Conditions(ds, {c});
    } catch (const datasets::DatasetError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(dataset_error(condition("blur")), "");
  Condition moved = condition("moved");
  moved.dataset.agents[1].camera_pose[1].p.x() += 1e-6;
  EXPECT_EQ(dataset_error(moved), "/data/moved/uav2/mav0/cam0_pose0/data.csv:3: condition moved does not image the "
                                  "reference /data/ds: the true camera pose at t_ns 100000000 differs from the "
                                  "reference's by 1e-06 (more than 1e-09)");
  Condition late = condition("late");
  late.dataset.agents[0].frames[2] += 1;
  EXPECT_NE(dataset_error(late).find("/data/late/uav1/mav0/cam0/data.csv:4: condition late does not image the reference "
                                     "/data/ds: frame 2 is at t_ns 200000001, the reference's at 200000000"),
            std::string::npos);
  Condition one = condition("one");
  one.dataset.agents.pop_back();
  EXPECT_NE(dataset_error(one).find("/data/one/dataset.yaml: condition one does not image the reference /data/ds: its "
                                    "cameras are on [uav1], the reference's on [uav1, uav2]"),
            std::string::npos);
  EXPECT_THROW(Conditions(ds, {condition("reference")}), std::invalid_argument);
  EXPECT_THROW(Conditions(ds, {condition("a/b")}), std::invalid_argument);
  EXPECT_THROW(Conditions(ds, {condition("blur"), condition("blur")}), std::invalid_argument);
}

}  // namespace
}  // namespace wingman::frontend_bench
