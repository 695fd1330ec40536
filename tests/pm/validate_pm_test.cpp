// validate_pm: the fixtures are valid, and each invariant, broken on purpose, is reported.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include "pm/progressive_mesh.h"
#include "pm_fixtures.h"
#include "test_support.h"
#include "util/chunked_loops.h"
#include "util/error.h"

namespace parapm {
namespace {

// validate_pm in chunks of a split or more each, on two threads: every test's PMs go through
// it too, and must fail with the very error the one-thread check gives.
ChunkedLoops split_chunks() { return ChunkedLoops(4, 2, 1); }

// validate_pm's error message, or "" when it accepts the PM.
std::string error_of(const std::function<void()>& validate) {
  try {
    validate();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidInput);
    return e.what();
  }
  return "";
}

// Expects validate_pm to throw kInvalidInput with `fragment` in its message, and the chunked
// check the same message.
void expect_invalid(const ProgressiveMesh& pm, const std::string& fragment) {
  const std::string error = error_of([&] { validate_pm(pm); });
  if (error.empty()) ADD_FAILURE() << "accepted; expected an error about '" << fragment << "'";
  EXPECT_NE(error.find(fragment), std::string::npos) << error;
  ChunkedLoops loops = split_chunks();
  EXPECT_EQ(error_of([&] { validate_pm(pm, loops); }), error);
}

void expect_valid(const ProgressiveMesh& pm) {
  EXPECT_NO_THROW(validate_pm(pm));
  ChunkedLoops loops = split_chunks();
  EXPECT_NO_THROW(validate_pm(pm, loops));
}

ProgressiveMesh with(ProgressiveMesh pm, const std::function<void(ProgressiveMesh&)>& edit) {
  edit(pm);
  return pm;
}

TEST(ValidatePm, FixturesAreValid) {
  expect_valid(testing::strip_pm());
  expect_valid(testing::octahedron_pm(false));
  expect_valid(testing::octahedron_pm(true));
  expect_valid(testing::cut_fan_pm());
  expect_valid(testing::random_pm(200, {false, true, false, 5}));
  expect_valid(ProgressiveMesh{});
}

// A PM of many splits in many chunks: a violation late in one chunk and one early in the next
// are reported in split order, whichever chunk finds its own first.
TEST(ValidatePm, ChunksReportTheFirstViolationInSplitOrder) {
  const ProgressiveMesh pm = testing::random_pm(200, {false, true, false, 5});
  ASSERT_GT(pm.splits.size(), 40u);
  ChunkedLoops loops(8, 2, 1);
  const size_t late = pm.splits.size() / 2 - 1, early = pm.splits.size() / 2 + 1;
  ProgressiveMesh broken = with(pm, [&](auto& p) {
    p.splits[early].vs = kNoId - 1;                      // a split's own check, in a later chunk
    p.splits[late].vs_before = p.splits[late].vt_after;  // the replay's, earlier
  });
  const std::string one_thread = error_of([&] { validate_pm(broken); });
  EXPECT_NE(one_thread.find("vsplit " + std::to_string(late) + ": vs_before"), std::string::npos)
      << one_thread;
  EXPECT_EQ(error_of([&] { validate_pm(broken, loops); }), one_thread);
  broken.splits[late] = pm.splits[late];
  EXPECT_NE(error_of([&] { validate_pm(broken, loops); }).find("vsplit " + std::to_string(early)),
            std::string::npos);
}

TEST(ValidatePm, Counts) {
  const ProgressiveMesh pm = testing::octahedron_pm(true);
  EXPECT_EQ(pm.full_vertex_count(), 9u);
  EXPECT_EQ(pm.full_face_count(), 14u);
  EXPECT_EQ(pm.full_wedge_count(), 10u);
  EXPECT_EQ(testing::strip_pm().full_face_count(), 6u);
}

TEST(ValidatePm, VertexIdsInRangeWhenTheSplitIsApplied) {
  const ProgressiveMesh strip = testing::strip_pm();
  expect_invalid(with(strip, [](auto& pm) { pm.splits[0].vs = 5; }), "vs 5 out of range");
  expect_invalid(with(strip, [](auto& pm) { pm.splits[1].vr = 6; }), "vr 6 out of range");
  expect_invalid(with(strip, [](auto& pm) { pm.splits[0].vl = 5; }), "vl 5 out of range");
  // vt of split 0 (5) is a valid vl for split 1.
  expect_invalid(with(strip,
                      [](auto& pm) {
                        pm.splits[1].vl = 5;
                        pm.splits[1].vr = 5;
                      }),
                 "vl and vr are both 5");
  expect_invalid(with(strip, [](auto& pm) { pm.splits[0].vl = kNoId; }), "neither vl nor vr");
  expect_invalid(with(strip, [](auto& pm) { pm.splits[0].vl = 1; }), "equals vs");
}

TEST(ValidatePm, PositionsAndErrors) {
  const ProgressiveMesh strip = testing::strip_pm();
  expect_invalid(with(strip,
                      [](auto& pm) {
                        pm.splits[0].vs_before = {1, 0, 0};
                      }),
                 "vs_before is not the position");
  expect_invalid(with(strip, [](auto& pm) { pm.splits[1].vt_after[2] = std::nan(""); }),
                 "non-finite");
  expect_invalid(with(strip, [](auto& pm) { pm.base.positions[4][0] = 0.1; }), "not a float32");
  expect_invalid(with(strip, [](auto& pm) { pm.splits[1].vs_after[0] = 0.1; }), "not a float32");
  expect_valid(with(strip, [](auto& pm) {
    pm.base.positions_are_float = false;
    pm.splits[1].vs_after[0] = 0.1;
  }));
  expect_invalid(with(strip, [](auto& pm) { pm.splits[1].error = 0.75f; }), "must not increase");
  expect_invalid(with(strip, [](auto& pm) { pm.splits[1].error = -1; }), "non-negative");
  expect_invalid(
      with(strip, [](auto& pm) { pm.splits[0].error = std::numeric_limits<float>::infinity(); }),
      "finite");
}

TEST(ValidatePm, BaseMesh) {
  const ProgressiveMesh strip = testing::strip_pm();
  expect_invalid(with(strip, [](auto& pm) { pm.base.faces[0][1] = 9; }), "names vertex 9");
  expect_invalid(with(strip, [](auto& pm) { pm.base.faces[0][1] = 0; }), "degenerate");
  expect_invalid(with(strip, [](auto& pm) { pm.base.wedge_vertex.push_back(0); }),
                 "no attribute channel");
}

TEST(ValidatePm, Wedges) {
  const ProgressiveMesh oct = testing::octahedron_pm(true);
  expect_invalid(with(oct, [](auto& pm) { pm.base.face_wedges[2][0] = 6; }), "names wedge 6");
  expect_invalid(with(oct, [](auto& pm) { pm.splits[0].corner_wedges[2] = 8; }),
                 "names wedge 8 but only 8 exist");
  expect_invalid(with(oct,
                      [](auto& pm) {
                        std::swap(pm.splits[0].corner_wedges[1], pm.splits[0].corner_wedges[4]);
                      }),
                 "used before new wedge 6");
  expect_invalid(with(oct,
                      [](auto& pm) {
                        pm.splits[1].corner_wedges[1] = 2;
                        pm.splits[1].corner_wedges[3] = 2;
                      }),
                 "introduces 1 wedges but its corners use 0");
  expect_invalid(with(oct, [](auto& pm) { pm.new_wedge_values.pop_back(); }), "new wedge values");
  expect_invalid(with(oct, [](auto& pm) { pm.wedge_changes[0].wedge = 6; }),
                 "changes wedge 6 but only 6 existed");
  expect_invalid(with(oct, [](auto& pm) { pm.wedge_change_values[1] = 0.25f; }),
                 "coarse value of wedge 4");
  expect_invalid(with(oct, [](auto& pm) { pm.wedge_changes[1].values_offset = 14; }),
                 "values out of range");
  expect_invalid(with(oct, [](auto& pm) { pm.wedge_changes[2].wedge = 0; }),
                 "changes wedge 0 twice");
  expect_invalid(with(oct, [](auto& pm) { pm.splits[2].wedge_changes_begin = 0; }),
                 "wedge changes begin at 0, expected 1");
  expect_invalid(with(oct, [](auto& pm) { pm.splits[2].wedge_changes_count = 5; }),
                 "run past the end");
  expect_invalid(with(oct, [](auto& pm) { pm.splits[0].corner_wedges[4] = kNoId; }),
                 "names wedge 4294967295");
  const ProgressiveMesh strip = testing::strip_pm();
  expect_invalid(with(strip, [](auto& pm) { pm.splits[0].corner_wedges[0] = 0; }), "no attributes");
  // An absent face's corners name no wedge.
  ProgressiveMesh open = testing::random_pm(50, {false, true, true, 3});
  for (VertexSplit& s : open.splits)
    if (!s.has_fl()) {
      s.corner_wedges[0] = 0;
      break;
    }
  expect_invalid(open, "of an absent face");
}

TEST(ValidatePm, CopiesAndOrders) {
  // Strip at full resolution: vertex 5 at (2,0,0); make a copy case by moving vertex 4's
  // last position there would break the fan's geometry, so use positions only.
  ProgressiveMesh strip = testing::strip_pm();
  strip.splits[0].vt_after = {2, 2, 0};  // vertex 5 ends where vertex 4 is
  ASSERT_NO_THROW(validate_pm(strip));
  expect_valid(with(strip, [](auto& pm) { pm.vertex_copies = {{5, 4}}; }));
  expect_invalid(with(strip,
                      [](auto& pm) {
                        pm.vertex_copies = {{5, 3}};
                      }),
                 "not at the position of its original");
  expect_invalid(with(strip, [](auto& pm) { pm.vertex_copies = {{5, 5}}; }), "copy of itself");
  expect_invalid(with(strip,
                      [](auto& pm) {
                        pm.vertex_copies = {{5, 4}, {5, 4}};
                      }),
                 "listed as a copy twice");
  expect_invalid(with(strip,
                      [](auto& pm) {
                        pm.vertex_copies = {{5, 4}, {4, 5}};
                      }),
                 "itself a copy");
  expect_invalid(with(strip, [](auto& pm) { pm.vertex_copies = {{7, 4}}; }), "out of range");

  auto ordered = [&](ProgressiveMesh pm) {
    pm.info.input_vertices = 7;
    pm.info.input_faces = 6;
    pm.input_vertex_order = {6, 5, 4, 3, 2, 1, 0};
    pm.input_face_order = {0, 1, 2, 3, 4, 5};
    return pm;
  };
  expect_valid(ordered(strip));
  expect_invalid(with(ordered(strip), [](auto& pm) { pm.input_vertex_order.pop_back(); }),
                 "6 entries for 7 vertices");
  expect_invalid(with(ordered(strip), [](auto& pm) { pm.input_vertex_order[0] = 5; }),
                 "input vertex 5 twice");
  expect_invalid(with(ordered(strip), [](auto& pm) { pm.info.input_faces = 5; }),
                 "the input had 5 faces");
  expect_invalid(with(ordered(strip), [](auto& pm) { pm.input_face_order[3] = 4; }),
                 "input face 4 twice");
  // A copy maps to its original's input vertex; an input vertex the repair removed leaves a
  // gap (the map is injective, not onto).
  expect_valid(with(ordered(strip), [](auto& pm) {
    pm.vertex_copies = {{5, 4}};
    pm.input_vertex_order = {0, 1, 2, 3, 6, 6, 5};
  }));
  expect_invalid(with(ordered(strip),
                      [](auto& pm) {
                        pm.vertex_copies = {{5, 4}};
                      }),
                 "different input vertices");
}

}  // namespace
}  // namespace parapm
