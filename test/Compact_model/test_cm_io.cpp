// Tests of the CM files (cm_io.h): bit-exact round trip, version 1 and 2, corrupt or truncated
// files.
#include "compact_model_test_util.h"

namespace {

// ------------------------------------------------------------------ CM files
TEST(CompactModelFile, RoundTripIsBitExact) {
  const Compact_model& m = sphere_model();
  const std::string bytes = cm_bytes(m);
  const Compact_model back = parse_cm(bytes);
  EXPECT_TRUE(back.vertices == m.vertices);
  EXPECT_TRUE(back.normals == m.normals);
  EXPECT_TRUE(back.surfaces == m.surfaces);
  EXPECT_TRUE(back.faces == m.faces);
  EXPECT_TRUE(back == m);
  EXPECT_EQ(cm_bytes(back), bytes);
  // Through a file, with texture coordinates and a cone.
  Compact_model t = m;
  t.uvs.resize(t.faces.size());
  for (std::size_t f = 0; f < t.faces.size(); ++f)
    t.uvs[f] = {{{float(f) / 1000.f, 0.25f}, {0.5f, float(f % 7) / 7.f}, {1.f, 0.f}}};
  t.texture = "textures/checker.png";
  t.surfaces[0].model = CONE_MODEL;
  t.surfaces[0].c[5] = -1;
  const std::string dir = cmgeom_test::scratch_dir();
  const std::string path = dir + "/model.cm";
  const std::size_t size = write_cm(path, t);
  EXPECT_EQ(size, std::filesystem::file_size(path));
  const Compact_model u = read_cm(path);
  EXPECT_TRUE(u == t);
  EXPECT_EQ(u.cone_vertices().size(), 1u);
  const Reconstruction r = reconstruct_regular(u, 1);
  EXPECT_EQ(r.corner_uvs.size(), 3 * r.triangles.size());
}

// The thesis' layout (version 1), written here independently of cm_io.h: faces as three
// (vertex, coefficient list, normal) triples.
std::string version1_bytes(const Compact_model& m) {
  std::string out("CMGEOMCM", 8);
  auto u8 = [&](unsigned v) { out.push_back(char(v & 0xffu)); };
  auto u32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) u8(v >> (8 * i));
  };
  auto u64 = [&](std::uint64_t v) {
    for (int i = 0; i < 8; ++i) u8(unsigned(v >> (8 * i)));
  };
  auto f32 = [&](double d) {
    const float f = float(d);
    std::uint32_t v;
    std::memcpy(&v, &f, 4);
    u32(v);
  };
  const std::vector<std::uint32_t> cones = m.cone_vertices();
  u32(1);
  u32(m.has_uvs() ? 1 : 0);
  for (std::size_t n : {m.vertices.size(), m.normals.size(), m.surfaces.size(), cones.size(), m.faces.size()}) u64(n);
  for (const auto& v : m.vertices) {
    f32(v.x);
    f32(v.y);
    f32(v.z);
  }
  for (const auto& v : m.normals) {
    f32(v.x);
    f32(v.y);
    f32(v.z);
  }
  for (const auto& s : m.surfaces) {
    u8(s.model);
    for (int k = 0; k < number_of_coefficients(s.model); ++k) f32(s.c[k]);
  }
  for (std::uint32_t c : cones) u32(c);
  for (const auto& f : m.faces)
    for (const Corner& c : f) {
      u32(c.vertex);
      u32(c.surface);
      u32(c.normal);
    }
  if (m.has_uvs()) {
    u32(std::uint32_t(m.texture.size()));
    out += m.texture;
    for (const auto& f : m.uvs)
      for (const auto& uv : f) {
        f32(uv[0]);
        f32(uv[1]);
      }
  }
  u64(CMGeom::CM::internal::fnv1a64(reinterpret_cast<const unsigned char*>(out.data()), out.size()));
  return out;
}

std::uint32_t le32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v |= std::uint32_t(std::uint8_t(b[at + std::size_t(i)])) << (8 * i);
  return v;
}

// `body` (a CM file without its checksum) with its checksum appended: a corruption that only
// the content checks can catch.
std::string with_checksum(std::string body) {
  const std::uint64_t h =
      CMGeom::CM::internal::fnv1a64(reinterpret_cast<const unsigned char*>(body.data()), body.size());
  for (int i = 0; i < 8; ++i) body.push_back(char((h >> (8 * i)) & 0xffu));
  return body;
}

// parse_cm() refuses `bytes` with an IO_error whose message contains `what`.
void expect_refused(const std::string& bytes, const std::string& what) {
  try {
    parse_cm(bytes, "bad.cm");
    ADD_FAILURE() << "no error, expected: " << what;
  } catch (const CMGeom::IO_error& e) {
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(CompactModelFile, Version2IsSmallerAndVersion1StillReads) {
  const Compact_model& m = sphere_model();
  // a built model: one (list, normal) pair per sector, numbered vertex by vertex
  const std::string v2 = cm_bytes(m);
  ASSERT_EQ(le32(v2, 8), 2u);
  EXPECT_EQ(le32(v2, 12), 2u) << "implicit sector table expected for a built model";
  // size from the layout: per face 12 bytes of vertex indices, plus one byte per corner at a
  // vertex with several sectors, plus one count byte per vertex
  std::vector<std::set<std::uint32_t>> sectors(m.vertices.size());
  for (const auto& f : m.faces)
    for (const Corner& c : f) sectors[c.vertex].insert(c.surface);
  std::size_t multi = 0;
  for (const auto& f : m.faces)
    for (const Corner& c : f) multi += sectors[c.vertex].size() > 1;
  std::size_t lists = 0;
  for (const auto& s : m.surfaces) lists += 1 + 4 * std::size_t(number_of_coefficients(s.model));
  const std::size_t expected = 56 + 12 * m.vertices.size() + 12 * m.normals.size() + lists +
                               4 * m.cone_vertices().size() + m.vertices.size() + 12 * m.faces.size() + multi + 8;
  EXPECT_EQ(v2.size(), expected);
  const std::string v1 = version1_bytes(m);
  EXPECT_EQ(v1.size() - v2.size(), 24 * m.faces.size() - m.vertices.size() - multi);
  // version 1 (the thesis' layout) reads to the same model, which is then written as version 2
  const Compact_model from_v1 = parse_cm(v1, "v1.cm");
  EXPECT_TRUE(from_v1 == m);
  EXPECT_EQ(cm_bytes(from_v1), v2);

  // An explicit sector table: normals and lists in another order than the sectors'.
  Compact_model p = m;
  std::reverse(p.normals.begin(), p.normals.end());
  for (auto& f : p.faces)
    for (Corner& c : f) c.normal = std::uint32_t(p.normals.size() - 1 - c.normal);
  const std::string pb = cm_bytes(p);
  EXPECT_EQ(le32(pb, 8), 2u);
  EXPECT_EQ(le32(pb, 12), 0u);
  EXPECT_TRUE(parse_cm(pb) == p);
  EXPECT_EQ(parse_cm(version1_bytes(p)), p);

  // A vertex with 256 sectors does not fit version 2's one-byte numbers: version 1 is written.
  Compact_model fan;
  fan.vertices.push_back(Vec3(0, 0, 0));
  const int n = 256;
  for (int i = 0; i < n; ++i) fan.vertices.push_back(Vec3(std::cos(2 * M_PI * i / n), std::sin(2 * M_PI * i / n), 0));
  for (int i = 0; i < n; ++i) {
    fan.normals.push_back(Vec3(0, 0, 1));
    Local_surface s;
    s.c[0] = 0.001 * i;
    fan.surfaces.push_back(s);
  }
  fan.normals.push_back(Vec3(0, 0, 1));
  fan.surfaces.push_back(Local_surface());
  const std::uint32_t shared = std::uint32_t(n);
  for (int i = 0; i < n; ++i)
    fan.faces.push_back({Corner{0, std::uint32_t(i), std::uint32_t(i)}, Corner{std::uint32_t(1 + i), shared, shared},
                         Corner{std::uint32_t(1 + (i + 1) % n), shared, shared}});
  round_to_float(fan);
  const std::string fb = cm_bytes(fan);
  EXPECT_EQ(le32(fb, 8), 1u);
  EXPECT_TRUE(parse_cm(fb) == fan);
  // 255 sectors fit
  fan.faces[0][0] = Corner{0, 1, 1};
  const std::string fb2 = cm_bytes(fan);
  EXPECT_EQ(le32(fb2, 8), 2u);
  EXPECT_TRUE(parse_cm(fb2) == fan);
  // the centre's 256 corners carry sector numbers (the last 256 bytes before the checksum); a
  // number out of range, checksum fixed, is a clear error
  std::string bad = fb2.substr(0, fb2.size() - 8);
  bad[bad.size() - 256] = char(255);
  expect_refused(with_checksum(bad), "face 0 corner 0: sector 255 of a vertex with 255");
}

// The reconstruction level a model was chosen for (Compact_model::reconstruction_level): one byte
// behind flag bit 3 in versions 1 and 2 (and 3, test_compact_file.cpp); a model without one
// writes the same bytes as before the field existed.
TEST(CompactModelFile, ReconstructionLevelSurvivesEveryVersion) {
  const Compact_model& m = sphere_model();
  ASSERT_EQ(m.reconstruction_level, -1);
  const std::string plain = cm_bytes(m);
  EXPECT_EQ(le32(plain, 12) & 8u, 0u);
  for (int level : {0, 3, 12}) {
    Compact_model l = m;
    l.reconstruction_level = level;
    const std::string b = cm_bytes(l);
    EXPECT_EQ(b.size(), plain.size() + 1);
    EXPECT_EQ(le32(b, 12), le32(plain, 12) | 8u);
    EXPECT_EQ(std::uint8_t(b[b.size() - 9]), level);  // the byte before the checksum
    const Compact_model back = parse_cm(b);
    EXPECT_EQ(back.reconstruction_level, level);
    EXPECT_TRUE(back == l);
    EXPECT_FALSE(back == m);
  }
  // version 1 (a vertex of 256 sectors) carries it as well
  Compact_model fan;
  fan.vertices.push_back(Vec3(0, 0, 0));
  const int n = 256;
  for (int i = 0; i < n; ++i) {
    fan.vertices.push_back(Vec3(std::cos(2 * M_PI * i / n), std::sin(2 * M_PI * i / n), 0));
    fan.normals.push_back(Vec3(0, 0, 1));
    fan.surfaces.push_back(Local_surface());
  }
  for (int i = 0; i < n; ++i)
    fan.faces.push_back({Corner{0, std::uint32_t(i), std::uint32_t(i)},
                         Corner{std::uint32_t(1 + i), std::uint32_t(i), std::uint32_t(i)},
                         Corner{std::uint32_t(1 + (i + 1) % n), std::uint32_t(i), std::uint32_t(i)}});
  fan.reconstruction_level = 4;
  const std::string fb = cm_bytes(fan);
  ASSERT_EQ(le32(fb, 8), 1u);
  EXPECT_EQ(parse_cm(fb).reconstruction_level, 4);
  // out of range: refused by the writer (validation) and, with the checksum fixed, by the reader
  Compact_model bad_level = m;
  bad_level.reconstruction_level = 13;
  EXPECT_THROW(cm_bytes(bad_level), CMGeom::Invalid_input);
  bad_level.reconstruction_level = 7;
  std::string b = cm_bytes(bad_level).substr(0, plain.size() + 1 - 8);
  b.back() = char(13);
  expect_refused(with_checksum(b), "reconstruction level 13 above 12");
}

TEST(CompactModelFile, CorruptOrTruncatedFilesGiveOneLineErrors) {
  const Compact_model& m = sphere_model();
  const std::string bytes = cm_bytes(m);
  auto expect_io_error = [](const std::string& b, const std::string& what) {
    try {
      parse_cm(b, "bad.cm");
      ADD_FAILURE() << what << ": no error";
    } catch (const CMGeom::IO_error& e) {
      const std::string msg = e.what();
      EXPECT_EQ(msg.find('\n'), std::string::npos);
      EXPECT_EQ(msg.rfind("bad.cm: ", 0), 0u) << msg;
    }
  };
  for (std::size_t len :
       {std::size_t(0), std::size_t(5), std::size_t(40), std::size_t(63), bytes.size() / 2, bytes.size() - 1})
    expect_io_error(bytes.substr(0, len), "truncated to " + std::to_string(len));
  // Every single-byte corruption is caught (structure, checksum or validation).
  for (std::size_t pos = 0; pos < bytes.size(); pos += std::max<std::size_t>(1, bytes.size() / 400)) {
    std::string b = bytes;
    b[pos] = char(b[pos] ^ 0x5a);
    expect_io_error(b, "byte " + std::to_string(pos));
  }
  std::string huge = bytes;
  huge[16] = char(0xff);
  huge[23] = char(0x7f);  // vertex count ~ 2^63
  expect_io_error(huge, "huge count");
  EXPECT_THROW(read_cm("/nonexistent/dir/x.cm"), CMGeom::IO_error);
}

}  // namespace
