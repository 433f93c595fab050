// Atomic write-if-changed, depfiles and deterministic EXR bytes.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <thread>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include "io/error.h"
#include "io/exr.h"
#include "io/fileio.h"
#include "io/png.h"
#include "io/repo_paths.h"

namespace fs = std::filesystem;
using namespace skybake;

namespace {
fs::path TempDir() {
  fs::path d = fs::temp_directory_path() / ("skybake_io_test_" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}
}  // namespace

TEST(FileIo, WriteIfChangedKeepsMtimeWhenEqual) {
  fs::path p = TempDir() / "sub" / "a.bin";
  EXPECT_TRUE(WriteFileIfChanged(p, "hello"));
  auto t0 = fs::last_write_time(p);
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  EXPECT_FALSE(WriteFileIfChanged(p, "hello"));
  EXPECT_EQ(fs::last_write_time(p), t0);
  EXPECT_TRUE(WriteFileIfChanged(p, "hello!"));
  EXPECT_EQ(ReadFileBytes(p), "hello!");
  // No temporary files are left behind.
  size_t n = 0;
  for (auto& e : fs::directory_iterator(p.parent_path())) n += e.is_regular_file();
  EXPECT_EQ(n, 1u);
}

// One transaction per command: nothing is visible before the commit, everything after it;
// an abort leaves the old files and no temporary file.
TEST(FileIo, TransactionRenamesTogetherOnlyAtCommit) {
  const fs::path d = TempDir() / "tx";
  fs::remove_all(d);
  fs::create_directories(d);
  WriteFileIfChanged(d / "a", "old a");
  WriteFileIfChanged(d / "b", "old b");
  BeginOutputTransaction();
  EXPECT_TRUE(WriteFileIfChanged(d / "a", "new a"));
  EXPECT_TRUE(WriteFileIfChanged(d / "b", "new b"));
  EXPECT_TRUE(WriteFileIfChanged(d / "b", "new b"));  // staged twice: one file, the last bytes
  EXPECT_EQ(ReadFileBytes(d / "a"), "old a");
  EXPECT_EQ(ReadFileBytes(d / "b"), "old b");
  EXPECT_EQ(CommitOutputTransaction(), 2u);
  EXPECT_EQ(ReadFileBytes(d / "a"), "new a");
  EXPECT_EQ(ReadFileBytes(d / "b"), "new b");
  // A failed command: its staged files go, the old ones stay.
  EXPECT_TRUE(WriteFileIfChanged(d / "a", "newer a"));
  AbortOutputTransaction();
  EXPECT_EQ(ReadFileBytes(d / "a"), "new a");
  std::vector<std::string> names;
  for (auto& e : fs::directory_iterator(d)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"a", "b"}));
}

// A run killed between its renames left a journal and one staged file; a live run's staged
// file is never touched.
TEST(FileIo, RecoveryCompletesDeadJournalsAndRemovesDeadTemporaries) {
  const fs::path d = TempDir() / "recover";
  fs::remove_all(d);
  fs::create_directories(d);
  const long dead = (1L << 22) + 4321;  // above the default pid_max: no such process
  const std::string t = ".tmp-" + std::to_string(dead);
  WriteFileIfChanged(d / "a", "new a");
  WriteFileIfChanged(d / "b", "old b");
  WriteFileIfChanged(d / ("b" + t), "new b");
  WriteFileIfChanged(d / ("orphan" + t), "half");
  const fs::path journal = d / (".skybake-commit-" + std::to_string(dead));
  WriteFileIfChanged(journal, (d / "a").string() + "\n" + (d / "b").string() + "\n");
  const std::string live = "live.tmp-" + std::to_string(::getpid());
  WriteFileIfChanged(d / live, "mine");
  RecoverOutputFolder(d);
  EXPECT_EQ(ReadFileBytes(d / "b"), "new b");
  std::vector<std::string> names;
  for (auto& e : fs::directory_iterator(d)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"a", "b", live}));
}

std::vector<std::string> Names(const fs::path& d) {
  std::vector<std::string> names;
  for (auto& e : fs::directory_iterator(d)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

// A reader honours the journal: reading any file of a folder whose journal a dead run left
// first completes that run's set (in every folder it spans), so the set is read complete.
TEST(FileIo, ReadingCompletesADeadRunsCommittedJournal) {
  const fs::path x = TempDir() / "read-x", y = TempDir() / "read-y";
  for (const fs::path& d : {x, y}) {
    fs::remove_all(d);
    fs::create_directories(d);
  }
  const long dead = (1L << 22) + 4322;  // above the default pid_max: no such process
  const std::string t = ".tmp-" + std::to_string(dead), j = ".skybake-commit-" + std::to_string(dead);
  // Killed after its commit point: a and b renamed, c still staged; c lies in another folder.
  WriteFileIfChanged(x / "a", "new a");
  WriteFileIfChanged(x / "b", "new b");
  WriteFileIfChanged(y / "c", "old c");
  WriteFileIfChanged(y / ("c" + t), "new c");
  const std::string list = (x / "a").string() + "\n" + (x / "b").string() + "\n" + (y / "c").string() + "\n";
  WriteFileIfChanged(x / j, list);
  WriteFileIfChanged(y / (j + t), list);  // y's copy was still pending when the run died
  EXPECT_EQ(ReadFileBytes(y / "c"), "new c");  // y's pending copy leads to x's named one
  EXPECT_EQ(Names(x), (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(Names(y), (std::vector<std::string>{"c"}));

  // Killed before its commit point (no copy has its name): the old set stays for readers, and
  // the next writer in that folder removes the pending copy and the staged file.
  WriteFileIfChanged(y / ("c" + t), "newer c");
  WriteFileIfChanged(y / (j + t), (y / "c").string() + "\n" + (y / "d").string() + "\n");
  EXPECT_EQ(ReadFileBytes(y / "c"), "new c");
  EXPECT_EQ(Names(y).size(), 3u);
  RecoverOutputFolder(y);
  EXPECT_EQ(Names(y), (std::vector<std::string>{"c"}));
  EXPECT_EQ(ReadFileBytes(y / "c"), "new c");
}

// A reader that meets a live commit's journal waits on its lock until the commit has ended, and
// then reads the new set.
TEST(FileIo, ReadingWaitsForALiveCommit) {
  const fs::path d = TempDir() / "read-live";
  fs::remove_all(d);
  fs::create_directories(d);
  const long pid = (1L << 22) + 4323;
  const std::string t = ".tmp-" + std::to_string(pid);
  const fs::path journal = d / (".skybake-commit-" + std::to_string(pid));
  WriteFileIfChanged(d / "a", "new a");
  WriteFileIfChanged(d / "b", "old b");
  WriteFileIfChanged(d / ("b" + t), "new b");
  WriteFileIfChanged(journal, (d / "a").string() + "\n" + (d / "b").string() + "\n");
  const int fd = ::open(journal.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX), 0);  // the writer's lock (another open file description)
  std::thread writer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    fs::rename(d / ("b" + t), d / "b");
    fs::remove(journal);
    ::close(fd);
  });
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(ReadFileBytes(d / "a"), "new a");
  EXPECT_EQ(ReadFileBytes(d / "b"), "new b");
  EXPECT_GE(std::chrono::steady_clock::now() - t0, std::chrono::milliseconds(250));
  writer.join();
  EXPECT_EQ(Names(d), (std::vector<std::string>{"a", "b"}));
}

// A commit across two folders leaves no journal and no temporary file in either.
TEST(FileIo, CommitAcrossFoldersLeavesNoJournal) {
  const fs::path x = TempDir() / "tx-x", y = TempDir() / "tx-y";
  for (const fs::path& d : {x, y}) fs::remove_all(d);
  BeginOutputTransaction();
  EXPECT_TRUE(WriteFileIfChanged(x / "a", "a"));
  EXPECT_TRUE(WriteFileIfChanged(y / "b", "b"));
  EXPECT_EQ(CommitOutputTransaction(), 2u);
  AbortOutputTransaction();
  EXPECT_EQ(Names(x), (std::vector<std::string>{"a"}));
  EXPECT_EQ(Names(y), (std::vector<std::string>{"b"}));
}

TEST(FileIo, Depfile) {
  fs::path d = TempDir() / "x.d";
  WriteDepfile(d, "out dir/a.exr", {"in.yaml", "data/a b.csv"});
  EXPECT_EQ(ReadFileBytes(d), "out\\ dir/a.exr: \\\n  in.yaml \\\n  data/a\\ b.csv\n");
}

TEST(FileIo, HashIsStable) {
  EXPECT_EQ(HashBytes("skybake"), HashBytes("skybake"));
  EXPECT_NE(HashBytes("skybake"), HashBytes("skybakf"));
  EXPECT_EQ(HashBytes("").size(), 16u);
}

TEST(Exr, TableRoundTripWithProvenance) {
  ExrTable t;
  t.axes.push_back({"altitude", "m", "test axis", {0.0, 100.0, 250.0}});
  t.axes.push_back({"wavelength", "nm", "second axis", {400.0, 500.0}});
  t.channels = {"a", "b"};
  t.channel_units = {"m^-3", "K"};
  for (size_t i = 0; i < 6; ++i) {
    t.values.push_back(static_cast<float>(i) * 1.5e20f);
    t.values.push_back(static_cast<float>(i));
  }
  ExrImage img = TableToImage(t);
  Provenance p;
  p.tool = "test";
  p.parameters = "x: 1\n";
  SetProvenance(img, p);
  img.chromaticities = XyzChromaticities();
  std::string bytes = EncodeExr(img);
  EXPECT_EQ(bytes, EncodeExr(img)) << "encoding must be deterministic";
  ExrImage back = DecodeExr(bytes, "mem.exr");
  EXPECT_EQ(back.strings.at("skybake.tool"), "test");
  EXPECT_EQ(back.strings.at("skybake.parameters"), "x: 1\n");
  ASSERT_TRUE(back.chromaticities.has_value());
  EXPECT_FLOAT_EQ(back.chromaticities->white.x, 1.0f / 3.0f);
  ExrTable t2 = ImageToTable(back, "mem.exr");
  ASSERT_EQ(t2.axes.size(), 2u);
  EXPECT_EQ(t2.axes[0].values, t.axes[0].values);
  EXPECT_EQ(t2.axes[1].unit, "nm");
  EXPECT_EQ(t2.channel_units, t.channel_units);
  EXPECT_EQ(t2.values, t.values);
}

// Provenance must not depend on the checkout the bake runs in: a repository file named by an
// absolute path (the CMF table or OCIO config a tool finds by itself) is recorded relative to the
// working directory, as the same file given relative is; a file outside the repository keeps the
// path it was given.
TEST(Exr, ProvenanceRecordsRepositoryFilesRelativeToTheWorkingDirectory) {
  const fs::path cmf = FindRepoFile("atmospheres/data/cie2006_2deg_xyz_cmf_1nm.csv");
  ASSERT_TRUE(cmf.is_absolute());
  const std::optional<fs::path> root = RepoRoot();
  ASSERT_TRUE(root.has_value());
  const fs::path outside = fs::absolute(TempDir() / "outside.csv");
  ASSERT_TRUE(WriteFileIfChanged(outside, "# source: test\nx,y\n1,2\n"));
  const fs::path before = fs::current_path();
  fs::current_path(*root / "tests");  // a folder inside the checkout, as outputs/ is for a bake
  Provenance p;
  p.AddInput(cmf);
  p.AddInput("../atmospheres/data/cie2006_2deg_xyz_cmf_1nm.csv");
  p.AddInput(outside);
  fs::current_path(before);
  ASSERT_EQ(p.inputs.size(), 3u);
  EXPECT_EQ(p.inputs[0].first, "../atmospheres/data/cie2006_2deg_xyz_cmf_1nm.csv");
  EXPECT_EQ(p.inputs[0], p.inputs[1]);
  EXPECT_EQ(p.inputs[2].first, outside.lexically_normal().generic_string());
}

TEST(Exr, TruncatedAndGarbageFilesAreInputErrors) {
  ExrImage img;
  img.Resize(64, 64, {"R", "G", "B"});
  for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = static_cast<float>(i % 97) * 0.37f;
  std::string bytes = EncodeExr(img);
  EXPECT_THROW(DecodeExr(bytes.substr(0, bytes.size() / 2), "half.exr"), InputError);
  EXPECT_THROW(DecodeExr("not an exr at all", "junk.exr"), InputError);
  try {
    ReadExr("/nonexistent.exr");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent.exr: cannot open file");
  }
}

// The message of the InputError `f` throws.
template <typename F>
std::string InputErrorOf(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

// The offset of the 4-byte size field of attribute `name` of type `type` in an EXR header.
size_t AttributeSizeAt(const std::string& bytes, const std::string& name, const std::string& type) {
  const std::string key = name + std::string(1, '\0') + type + std::string(1, '\0');
  const size_t at = bytes.find(key);
  EXPECT_NE(at, std::string::npos) << name;
  return at + key.size();
}

void StoreI32(std::string& bytes, size_t at, int32_t v) {
  for (int i = 0; i < 4; ++i) bytes[at + i] = static_cast<char>((static_cast<uint32_t>(v) >> (8 * i)) & 0xff);
}

// A table axis value that is not a number is a bad file, not std::stod's std::invalid_argument
// (found by the EXR fuzz target; tests/fuzz/regressions/exr/axis_value_not_a_number.exr).
TEST(Exr, AxisValuesThatAreNotFiniteNumbersAreInputErrors) {
  ExrTable t;
  t.axes.push_back({"altitude", "m", "test axis", {0.0, 100.0, 250.0}});
  t.channels = {"a"};
  t.channel_units = {"m^-3"};
  t.values = {1.0f, 2.0f, 3.0f};
  for (const std::string bad : {"0 x 250", "0 1e999 250", "0 nan 250", "0  250", "0 100 250z"}) {
    ExrImage img = TableToImage(t);
    img.strings["skybake.axis0.values"] = bad;
    const ExrImage back = DecodeExr(EncodeExr(img), "t.exr");
    EXPECT_NE(InputErrorOf([&] { (void)ImageToTable(back, "t.exr"); })
                  .find("t.exr: attribute skybake.axis0.values: '"),
              std::string::npos)
        << bad;
  }
  const std::string file = ReadFileBytes(std::filesystem::path(SKYBAKE_SOURCE_DIR) /
                                         "tests/fuzz/regressions/exr/axis_value_not_a_number.exr");
  for (const ExrPart& p : DecodeExrParts(file, "crash.exr")) {
    EXPECT_THROW((void)ImageToTable(p.image, "crash.exr"), InputError);
  }
}

// Header fields that the file cannot hold are refused before OpenEXR allocates from them (the
// EXR fuzz target ran at 4 inputs/s while OpenEXR allocated and cleared gigabytes for such fields).
TEST(Exr, HeaderFieldsTheFileCannotHoldAreRefusedBeforeDecoding) {
  ExrImage img;
  img.Resize(4, 3, {"x"});
  img.strings["skybake.note"] = "a note";
  const std::string good = EncodeExr(img);
  ASSERT_NO_THROW(DecodeExr(good, "g.exr"));

  std::string huge = good;  // a string attribute claiming 2 GiB
  StoreI32(huge, AttributeSizeAt(huge, "skybake.note", "string"), 0x7fffffff);
  EXPECT_NE(InputErrorOf([&] { (void)DecodeExr(huge, "h.exr"); })
                .find("h.exr: not a readable OpenEXR file: attribute 'skybake.note' claims 2147483647 bytes"),
            std::string::npos);

  std::string shrunk = good;  // a box2i declared with 0 bytes: OpenEXR would read 16 anyway
  StoreI32(shrunk, AttributeSizeAt(shrunk, "displayWindow", "box2i"), 0);
  EXPECT_EQ(InputErrorOf([&] { (void)DecodeExr(shrunk, "s.exr"); }),
            "s.exr: not a readable OpenEXR file: attribute 'displayWindow' of type box2i has 0 bytes, not 16");

  std::string tall = good;  // 10^7 scanlines: 10^7 chunk offsets in a file of a few hundred bytes
  StoreI32(tall, AttributeSizeAt(tall, "dataWindow", "box2i") + 4 + 12, 9999999);
  EXPECT_NE(InputErrorOf([&] { (void)DecodeExr(tall, "t.exr"); }).find("t.exr: not a readable OpenEXR file: "),
            std::string::npos);

  // 100 x 100 values need 20 000 bytes uncompressed (NONE, ratio 1); the file has a few hundred.
  // The same window with ZIP (ratio up to 1032) passes this check and fails on its missing data.
  std::string wide = good;
  StoreI32(wide, AttributeSizeAt(wide, "dataWindow", "box2i") + 4 + 8, 99);
  StoreI32(wide, AttributeSizeAt(wide, "dataWindow", "box2i") + 4 + 12, 99);
  std::string wide_none = wide;
  wide_none[AttributeSizeAt(wide_none, "compression", "compression") + 4] = 0;
  EXPECT_EQ(InputErrorOf([&] { (void)DecodeExr(wide_none, "w.exr"); }),
            fmt::format("w.exr: not a readable OpenEXR file: a data window of 100 x 100 with 1 channels is more than "
                        "{} bytes can hold",
                        wide.size()));
  EXPECT_EQ(InputErrorOf([&] { (void)DecodeExr(wide, "w.exr"); }).find("can hold"), std::string::npos);

  std::vector<ExrPart> parts = {{"first", img}, {"second", img}};
  std::string many = EncodeExrParts(parts);  // a part claiming 10^8 chunks
  StoreI32(many, AttributeSizeAt(many, "chunkCount", "int") + 4, 100000000);
  EXPECT_NE(InputErrorOf([&] { (void)DecodeExrParts(many, "m.exr"); })
                .find("m.exr: not a readable OpenEXR file: 100000000 chunks need 800000000 bytes of offsets"),
            std::string::npos);

  EXPECT_EQ(InputErrorOf([&] { (void)DecodeExr(good.substr(0, 40), "c.exr"); }).rfind("c.exr: not a readable OpenEXR file: ", 0),
            0u);
}

// A data window that does not start at 0,0 (OpenEXR allows any origin) reads back its pixels,
// without a frame-buffer base pointer outside the buffer (UBSan's pointer overflow, found by the
// EXR fuzz target; tests/fuzz/regressions/exr/data_window_off_origin.exr).
TEST(Exr, DataWindowAwayFromTheOriginReadsBack) {
  const fs::path p = TempDir() / "offset.exr";
  const Imath::Box2i dw(Imath::V2i(-3, 5), Imath::V2i(0, 6));  // 4 x 2 pixels
  std::vector<float> px(8);
  for (size_t i = 0; i < px.size(); ++i) px[i] = 0.5f * static_cast<float>(i);
  {
    Imf::Header h(dw, dw);
    h.channels().insert("x", Imf::Channel(Imf::FLOAT));
    Imf::OutputFile out(p.c_str(), h, 1);
    Imf::FrameBuffer fb;
    fb.insert("x", Imf::Slice::Make(Imf::FLOAT, px.data(), dw, sizeof(float), 4 * sizeof(float)));
    out.setFrameBuffer(fb);
    out.writePixels(2);
  }
  const ExrImage img = ReadExr(p);
  EXPECT_EQ(img.width, 4);
  EXPECT_EQ(img.height, 2);
  EXPECT_EQ(img.pixels, px);
  const std::string file = ReadFileBytes(std::filesystem::path(SKYBAKE_SOURCE_DIR) /
                                         "tests/fuzz/regressions/exr/data_window_off_origin.exr");
  try {
    for (const ExrPart& part : DecodeExrParts(file, "crash.exr")) (void)part;
  } catch (const InputError&) {
  }
}

// A chunk whose size field makes OpenEXR ask the input stream for a negative number of bytes
// is a bad file (UBSan's pointer overflow in the stream, found by the EXR fuzz target).
TEST(Exr, NegativeReadSizeIsAnInputError) {
  const std::string file = ReadFileBytes(std::filesystem::path(SKYBAKE_SOURCE_DIR) /
                                         "tests/fuzz/regressions/exr/negative_read_size.exr");
  EXPECT_NE(InputErrorOf([&] { (void)DecodeExrParts(file, "n.exr"); }).find("n.exr: not a readable OpenEXR file"),
            std::string::npos);
}

TEST(Exr, MultiPartRoundTrip) {
  ExrImage a, b;
  a.Resize(3, 2, {"x"});
  b.Resize(5, 1, {"u", "v"});
  for (size_t i = 0; i < a.pixels.size(); ++i) a.pixels[i] = static_cast<float>(i);
  for (size_t i = 0; i < b.pixels.size(); ++i) b.pixels[i] = -static_cast<float>(i);
  b.strings["skybake.note"] = "second";
  std::string bytes = EncodeExrParts({{"first", a}, {"second", b}});
  EXPECT_EQ(bytes, EncodeExrParts({{"first", a}, {"second", b}}));
  std::vector<ExrPart> back = DecodeExrParts(bytes, "mem.exr");
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(FindPart(back, "first", "mem.exr").pixels, a.pixels);
  EXPECT_EQ(FindPart(back, "second", "mem.exr").pixels, b.pixels);
  EXPECT_EQ(FindPart(back, "second", "mem.exr").strings.at("skybake.note"), "second");
  EXPECT_THROW(FindPart(back, "third", "mem.exr"), InputError);
}

TEST(Png, RoundTripAndDeterminism) {
  std::vector<uint8_t> px(4 * 3 * 3);
  for (size_t i = 0; i < px.size(); ++i) px[i] = static_cast<uint8_t>(i * 7);
  std::string bytes = EncodePng8(4, 3, 3, px);
  EXPECT_EQ(bytes, EncodePng8(4, 3, 3, px));
  int w = 0, h = 0, c = 0;
  EXPECT_EQ(DecodePng8(bytes, "mem.png", &w, &h, &c), px);
  EXPECT_EQ(w, 4);
  EXPECT_EQ(h, 3);
  EXPECT_EQ(c, 3);
  EXPECT_THROW(DecodePng8("garbage!", "g.png", &w, &h, &c), InputError);
}
