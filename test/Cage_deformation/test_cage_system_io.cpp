// Tests of the cage-system file: inline and file cages, round trip, errors naming the file and
// the JSON pointer.
#include "cage_system_test_util.h"

namespace {

std::string write(const std::string& name, const std::string& text) {
  const std::string p = tmp(name);
  std::ofstream(p) << text;
  return p;
}

const char* cube_json =
    R"({"vertices": [[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,1]],
        "faces": [[0,4,6,2],[1,3,7,5],[0,1,5,4],[2,6,7,3],[0,2,3,1],[4,5,7,6]]})";

}  // namespace

// ------------------------------------------------------------------ file format
TEST(Cage_system_io, reads_inline_and_file_cages_and_round_trips) {
  std::ofstream(tmp("cube.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
                                    "f 1 5 7 3\nf 2 4 8 6\nf 1 2 6 5\nf 3 7 8 4\nf 1 3 4 2\nf 5 6 8 7\n";
  const std::string path = write(
      "ok.json", std::string(R"({"h": 0.5, "join_coordinates": "mean_value", "cages": [
      {"name": "a", "rest": )") +
                     cube_json + R"(, "deformed": [[0,0,0],[1,0,0],[0,1,0],[1,1,0],[0,0,1],[1,0,1],[0,1,1],[1,1,2]]},
      {"name": "b", "rest": "cage_system_cube.obj", "coordinates": "green", "h": 0.25,
       "border_h": [{"cage": "a", "h": 0.125}], "parent": {"cage": "a", "vertices": [0, 7]}}]})");
  const Cage_system_description d = read_cage_system(path);
  ASSERT_EQ(d.cages.size(), 2u);
  EXPECT_EQ(d.cages[0].h, 0.5);
  EXPECT_EQ(d.cages[1].h, 0.25);
  EXPECT_EQ(d.cages[1].coordinates, Coordinate_type::green);
  EXPECT_EQ(d.cages[0].rest.triangles.size(), 12u);
  EXPECT_EQ(d.cages[0].deformed[7][2], 2.0);
  ASSERT_EQ(d.cages[1].parents.size(), 1u);
  EXPECT_EQ(d.cages[1].parents[0].cage, 0u);
  EXPECT_EQ(d.cages[1].parents[0].vertices, (std::vector<std::uint32_t>{0, 7}));
  ASSERT_EQ(d.cages[1].border_h.size(), 1u);
  EXPECT_EQ(d.cages[1].border_h[0].cage, 0u);
  EXPECT_EQ(d.cages[1].border_h[0].h, 0.125);
  EXPECT_TRUE(d.cages[0].border_h.empty());
  // Round trip through the inline writer.
  write_cage_system(tmp("rt.json"), d);
  const Cage_system_description e = read_cage_system(tmp("rt.json"));
  ASSERT_EQ(e.cages.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(e.cages[c].rest.vertices, d.cages[c].rest.vertices);
    EXPECT_EQ(e.cages[c].rest.triangles, d.cages[c].rest.triangles);
    EXPECT_EQ(e.cages[c].deformed, d.cages[c].deformed);
    EXPECT_EQ(e.cages[c].h, d.cages[c].h);
    EXPECT_EQ(e.cages[c].coordinates, d.cages[c].coordinates);
    ASSERT_EQ(e.cages[c].border_h.size(), d.cages[c].border_h.size());
    for (std::size_t k = 0; k < d.cages[c].border_h.size(); ++k) {
      EXPECT_EQ(e.cages[c].border_h[k].cage, d.cages[c].border_h[k].cage);
      EXPECT_EQ(e.cages[c].border_h[k].h, d.cages[c].border_h[k].h);
    }
  }
  EXPECT_EQ(e.cages[1].parents[0].vertices, d.cages[1].parents[0].vertices);
}

// The harmonic options, "outside" included, are read and written back.
TEST(Cage_system_io, harmonic_options_round_trip) {
  const std::string path = write("harmonic.json", std::string(R"({"cages": [
      {"rest": )") + cube_json + R"(, "coordinates": "harmonic",
       "harmonic": {"resolution": 24, "interpolation": "trilinear", "outside": "mean_value"}},
      {"rest": )" + cube_json + R"(, "coordinates": "harmonic"}]})");
  const Cage_system_description d = read_cage_system(path);
  ASSERT_EQ(d.cages.size(), 2u);
  EXPECT_EQ(d.cages[0].harmonic.resolution, 24);
  EXPECT_EQ(d.cages[0].harmonic.interpolation, Harmonic_interpolation::trilinear);
  EXPECT_EQ(d.cages[0].harmonic.outside, Harmonic_outside::mean_value);
  EXPECT_EQ(d.cages[1].harmonic.outside, Harmonic_outside::undefined);  // the default
  write_cage_system(tmp("harmonic_rt.json"), d);
  const Cage_system_description e = read_cage_system(tmp("harmonic_rt.json"));
  ASSERT_EQ(e.cages.size(), 2u);
  for (std::size_t c = 0; c < 2; ++c) {
    EXPECT_EQ(e.cages[c].harmonic.resolution, d.cages[c].harmonic.resolution);
    EXPECT_EQ(e.cages[c].harmonic.interpolation, d.cages[c].harmonic.interpolation);
    EXPECT_EQ(e.cages[c].harmonic.outside, d.cages[c].harmonic.outside);
  }
}

TEST(Cage_system_io, errors_name_the_file_and_the_json_pointer) {
  const std::string c = cube_json;
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"{", "invalid JSON"},
      {"[]", "/: expected a JSON object"},
      {R"({"cages": []})", "/cages: expected a non-empty array"},
      {R"({"cages": [{"rest": )" + c + R"(, "h": 0}]})", "/cages/0/h: must be a number in (0, 1]"},
      {R"({"cages": [{"rest": )" + c + R"(, "hh": 1}]})", "/cages/0/hh: unknown key"},
      {R"({"cages": [{"rest": )" + c + R"(, "coordinates": "wachspress"}]})",
       "/cages/0/coordinates: unknown coordinates"},
      {R"({"cages": [{"rest": )" + c + R"(, "deformed": [[0,0,0]]}]})", "/cages/0/deformed: has 1 vertices"},
      {R"({"cages": [{"rest": {"vertices": [[0,0,0],[1,0,0],[0,1,0],[0,0,"x"]], "faces": [[0,1,2]]}}]})",
       "/cages/0/rest/vertices/3/2: must be a number"},
      {R"({"cages": [{"rest": {"vertices": [[0,0,0],[1,0,0],[0,1,0],[0,0,1]], "faces": [[0,1,2],[0,1,3]]}}]})",
       "/cages/0/rest:"},
      {R"({"cages": [{"rest": {"vertices": [[0,0,0]], "faces": [[0,1,7]]}}]})",
       "/cages/0/rest/faces/0/1: index out of range"},
      {R"({"cages": [{"rest": )" + c + R"(, "parent": {"cage": 0}}]})",
       "/cages/0/parent/cage: a cage cannot be its own parent"},
      {R"({"cages": [{"rest": )" + c + R"(, "parent": {"cage": 1}}, {"rest": )" + c + R"(, "parent": {"cage": 0}}]})",
       "the parent links form a cycle"},
      {R"({"cages": [{"rest": )" + c + R"(, "parent": [{"cage": 1, "vertices": [1]}, {"cage": 2, "vertices": [1]}]},
                     {"rest": )" +
           c + R"(}, {"rest": )" + c + R"(}]})",
       "owned twice"},
      {R"({"cages": [{"rest": "no_such_file.obj"}]})", "/cages/0/rest: "},
      {R"({"join_coordinates": "green", "cages": [{"rest": )" + c + R"(}]})", "/join_coordinates: join cages need C1"},
      {R"({"cages": [{"rest": )" + c + R"(, "harmonic": {"resolution": 4}}]})", "/cages/0/harmonic/resolution"},
      {R"({"cages": [{"rest": )" + c + R"(, "harmonic": {"outside": "clamp"}}]})",
       "/cages/0/harmonic/outside: must be \"undefined\" or \"mean_value\""},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": {"cage": 1, "h": 0.5}}, {"rest": )" + c + R"(}]})",
       "/cages/0/border_h: must be an array"},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": [{"cage": 1, "h": 1.5}]}, {"rest": )" + c + R"(}]})",
       "/cages/0/border_h/0/h: must be a number in (0, 1]"},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": [{"cage": "x", "h": 0.5}]}]})",
       "/cages/0/border_h/0/cage: no cage has this name"},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": [{"cage": 0, "h": 0.5}]}]})",
       "/cages/0/border_h/0/cage: a cage has no border with itself"},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": [{"cage": 1, "h": 0.5}, {"cage": 1, "h": 0.2}]},
                     {"rest": )" +
           c + R"(}]})",
       "/cages/0/border_h/1/cage: this border is given twice"},
      {R"({"cages": [{"rest": )" + c + R"(, "border_h": [{"h": 0.5}]}]})", "/cages/0/border_h/0/cage: missing"},
  };
  for (const auto& [text, expect] : cases) {
    const std::string p = write("bad.json", text);
    try {
      read_cage_system(p);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const CMGeom::IO_error& e) {
      const std::string w = e.what();
      EXPECT_NE(w.find(p), std::string::npos) << w;
      EXPECT_NE(w.find(expect), std::string::npos) << w << "\nexpected: " << expect;
      EXPECT_EQ(w.find('\n'), std::string::npos) << w;
    }
  }
}
