// The OpenNI2 path, through OpenNI2 itself: our simulated-depth OpenNI2 driver serves frames
// of `hpose simulate` as a device; OpenNI2's recorder writes them to .oni; OpenNI2's file driver
// plays the .oni back. The test runs with LD_LIBRARY_PATH pointing at the staged OpenNI2
// directory of the build (see server/openni2_driver/CMakeLists.txt).
#include <OpenNI.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/io/atomic_file.h"
#include "core/io/depth_png.h"
#include "core/io/intrinsics_json.h"
#include "server/frame_source.h"
#include "server/openni2_devices.h"
#include "server/openni2_recorder.h"
#include "server/openni2_source.h"
#include "tests/integration/hposed_process.h"
#include "tests/integration/test_util.h"
#include "tests/sanitizer_build.h"

namespace hpose::server {
namespace {

namespace tu = hpose::testing_util;

class Openni2Test : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new std::string(tu::MakeTempDir("openni2"));
    ASSERT_TRUE(tu::SimulateFrames(*dir_ + "/frames", 3));
    // Read by the driver when OpenNI2 initialises (every Open of a source).
    setenv("HPOSE_SIM_DEPTH_DIR", (*dir_ + "/frames").c_str(), 1);
    setenv("HPOSE_SIM_DEPTH_FPS", "30", 1);
  }
  static void TearDownTestSuite() {
    std::filesystem::remove_all(*dir_);
    delete dir_;
  }
  static DepthImage Png(int i) {
    Result<DepthImage> d = ReadDepthPng(*dir_ + "/frames/depth_00" + std::to_string(i) + ".png");
    EXPECT_TRUE(d.ok());
    return d.ok() ? *d : DepthImage();
  }
  // Index of the simulated frame equal to `depth`, or -1.
  static int MatchingFrame(const DepthImage& depth) {
    for (int i = 0; i < 3; ++i) {
      if (Png(i).mm == depth.mm) return i;
    }
    return -1;
  }
  static std::string* dir_;
};

std::string* Openni2Test::dir_ = nullptr;

TEST_F(Openni2Test, DeviceServesTheSimulatedFramesThroughOpenni2) {
  Openni2Source source("openni2://", Openni2SourceOptions{});
  Status opened = source.Open();
  ASSERT_TRUE(opened.ok()) << opened.error().ToString();
  EXPECT_TRUE(source.live());
  EXPECT_EQ(source.kind(), "openni2-device");
  Result<Intrinsics> k = ReadIntrinsicsJson(*dir_ + "/frames/intrinsics.json");
  ASSERT_TRUE(k.ok());
  std::uint64_t last = 0;
  for (int i = 0; i < 4; ++i) {
    Result<Frame> f = source.Next();
    ASSERT_TRUE(f.ok()) << f.error().ToString();
    EXPECT_GT(f->sequence, last);
    last = f->sequence;
    ASSERT_EQ(f->depth.width, 320);
    ASSERT_EQ(f->depth.height, 240);
    EXPECT_GE(MatchingFrame(f->depth), 0) << "frame " << i << " is not one of the served PNGs";
    // OpenNI2 carries the field of view only; focal lengths come back through it.
    EXPECT_NEAR(f->intrinsics.fx, k->fx, 1e-3 * k->fx);
    EXPECT_NEAR(f->intrinsics.fy, k->fy, 1e-3 * k->fy);
  }
  source.Close();
}

TEST_F(Openni2Test, MissingDeviceUriIsUnavailable) {
  Openni2Source source("openni2://no-such-device", Openni2SourceOptions{});
  Status opened = source.Open();
  ASSERT_FALSE(opened.ok());
  EXPECT_EQ(opened.error().code, ErrorCode::kUnavailable);
  EXPECT_NE(opened.error().message.find("no-such-device"), std::string::npos);
}

TEST_F(Openni2Test, RecordsOniAndPlaysItBackThroughTheFileDriver) {
  const std::string oni = *dir_ + "/walk.oni";
  // What a recording of walk.oni killed mid-way leaves (no process has this id: Linux's stop at
  // pid_max, at most 2^22); recording walk.oni again removes it.
  const std::string killed = *dir_ + "/.walk.oni.tmp." + std::to_string((1 << 22) + 1) + ".0";
  ASSERT_TRUE(WriteFileAtomically(killed, "half a recording").ok());
  RecordOptions options;
  options.frames = 6;
  Result<RecordSummary> rec = RecordOpenni2("openni2://", oni, options, nullptr);
  ASSERT_TRUE(rec.ok()) << rec.error().ToString();
  EXPECT_FALSE(std::filesystem::exists(killed));
  // Every frame read is in the file; the device may have sent a few more while the recording
  // stopped (30 frames a second), and the summary counts the file's.
  EXPECT_GE(rec->frames, 6);
  EXPECT_LE(rec->frames, 6 + 15);
  EXPECT_EQ(rec->format, "oni");
  ASSERT_TRUE(std::filesystem::file_size(oni) > 1000);

  ReplayOptions replay;
  replay.realtime = false;
  Result<std::unique_ptr<FrameSource>> source = MakeFrameSource(oni, replay);
  ASSERT_TRUE(source.ok()) << source.error().ToString();
  EXPECT_EQ((*source)->kind(), "oni");
  Status opened = (*source)->Open();
  ASSERT_TRUE(opened.ok()) << opened.error().ToString();
  EXPECT_EQ((*source)->frame_count(), rec->frames);
  int frames = 0;
  double last_time = -1.0;
  while (true) {
    Result<Frame> f = (*source)->Next();
    if (!f.ok()) {
      EXPECT_EQ(f.error().code, ErrorCode::kOutOfRange) << f.error().ToString();
      break;
    }
    ++frames;
    EXPECT_GE(MatchingFrame(f->depth), 0) << "played-back frame " << frames << " differs";
    EXPECT_GT(f->source_time_s, last_time);
    last_time = f->source_time_s;
    ASSERT_LE(frames, rec->frames);
  }
  EXPECT_EQ(frames, rec->frames);
  (*source)->Close();

  // hpose replay reads the same recording and writes one JSON line per frame.
  std::string out;
  ASSERT_EQ(tu::RunCommand(tu::HposeProgram() + " replay '" + oni + "' --no-progress --template " +
                               tu::TemplatePath("standing") + " 2>/dev/null",
                           &out),
            0);
  std::istringstream lines(out);
  std::string line;
  int n = 0;
  while (std::getline(lines, line)) {
    ++n;
    EXPECT_NE(line.find("\"depth_template\""), std::string::npos) << line.substr(0, 200);
    EXPECT_NE(line.find("\"template_name\":\"standing\""), std::string::npos);
  }
  EXPECT_EQ(n, rec->frames);
}

TEST_F(Openni2Test, AnOniRecordingCountsTheFramesItHoldsNotTheFramesRead) {
  // A read late by 200 ms at 30 frames a second: the recorder keeps the frames that arrived
  // meanwhile, which were never read, and the summary says how many the file holds.
  const std::string oni = *dir_ + "/late.oni";
  RecordOptions options;
  options.frames = 4;
  long reads = 0;
  Result<RecordSummary> rec = RecordOpenni2("openni2://", oni, options, [&](long n) {
    reads = n;
    if (n == 1) std::this_thread::sleep_for(std::chrono::milliseconds(200));
    return true;
  });
  ASSERT_TRUE(rec.ok()) << rec.error().ToString();
  EXPECT_EQ(reads, 4);
  EXPECT_GE(rec->frames, 4 + 3);

  ReplayOptions replay;
  replay.realtime = false;
  Result<std::unique_ptr<FrameSource>> source = MakeFrameSource(oni, replay);
  ASSERT_TRUE(source.ok()) << source.error().ToString();
  ASSERT_TRUE((*source)->Open().ok());
  EXPECT_EQ((*source)->frame_count(), rec->frames);
  long played = 0;
  while ((*source)->Next().ok()) ++played;
  EXPECT_EQ(played, rec->frames);
  (*source)->Close();
}

// Two threads spinning for as long as it lives: a busy machine, where a thread just created
// may wait to run.
class BusyCores {
 public:
  BusyCores() {
    for (int i = 0; i < 2; ++i) {
      threads_.emplace_back([this] {
        volatile unsigned long spins = 0;
        while (busy_.load(std::memory_order_relaxed)) spins = spins + 1;
      });
    }
  }
  ~BusyCores() {
    busy_ = false;
    for (std::thread& t : threads_) t.join();
  }

 private:
  std::atomic<bool> busy_{true};
  std::vector<std::thread> threads_;
};

// OpenNI2's file player marks itself running in its own thread. A recording closed before that
// thread first ran left it running; OpenNI2 cancelled it 3 s later, a crash once its driver was
// unloaded. `open_and_close(i)` opens and closes one, at once, 40 times on a busy machine; each
// close must come sooner than OpenNI2's 3 s wait for a player that does not stop.
void ExpectPromptCloses(const std::function<void(int)>& open_and_close) {
  BusyCores busy;
  for (int i = 0; i < 40; ++i) {
    const auto start = std::chrono::steady_clock::now();
    open_and_close(i);
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::milliseconds(2500))
        << "open and close " << i;
  }
}

Openni2SourceOptions AsFastAsRead() {
  Openni2SourceOptions options;
  options.replay.realtime = false;
  return options;
}

TEST_F(Openni2Test, ARecordingOpenedAndClosedAtOnceStopsItsPlayer) {
  const std::string oni = *dir_ + "/short.oni";
  RecordOptions options;
  options.frames = 2;
  ASSERT_TRUE(RecordOpenni2("openni2://", oni, options, nullptr).ok());
  ExpectPromptCloses([&](int i) {
    Openni2Source source(oni, AsFastAsRead());
    ASSERT_TRUE(source.Open().ok()) << i;
    EXPECT_GE(source.frame_count(), 2);
    source.Close();
  });
}

// Sets an environment variable of the simulated driver for one scope, then puts back what was
// there (read by the driver when OpenNI2 initialises, that is at every open).
class ScopedEnv {
 public:
  ScopedEnv(const char* name, const std::string& value) : name_(name) {
    const char* before = std::getenv(name);
    had_ = before != nullptr;
    if (had_) before_ = before;
    setenv(name, value.c_str(), 1);
  }
  ~ScopedEnv() {
    if (had_) {
      setenv(name_, before_.c_str(), 1);
    } else {
      unsetenv(name_);
    }
  }

 private:
  const char* name_;
  bool had_ = false;
  std::string before_;
};

// Records the simulated device's `sensors` to `oni` with OpenNI2's own recorder (hpose record
// takes depth only) until the first of them has delivered `frames` frames.
bool RecordWithOpenni2(const std::string& oni, int frames,
                       const std::vector<openni::SensorType>& sensors) {
  bool ok = openni::OpenNI::initialize() == openni::STATUS_OK;
  {
    openni::Device device;
    std::vector<openni::VideoStream> streams(sensors.size());
    openni::Recorder recorder;
    ok = ok && device.open(openni::ANY_DEVICE) == openni::STATUS_OK &&
         recorder.create(oni.c_str()) == openni::STATUS_OK;
    for (size_t i = 0; ok && i < sensors.size(); ++i) {
      ok = streams[i].create(device, sensors[i]) == openni::STATUS_OK &&
           recorder.attach(streams[i]) == openni::STATUS_OK;
    }
    ok = ok && recorder.start() == openni::STATUS_OK;
    for (size_t i = 0; ok && i < sensors.size(); ++i) {
      ok = streams[i].start() == openni::STATUS_OK;
    }
    for (int i = 0; ok && i < frames; ++i) {
      openni::VideoFrameRef frame;
      ok = streams[0].readFrame(&frame) == openni::STATUS_OK;
    }
    for (openni::VideoStream& stream : streams) stream.stop();
    recorder.stop();
    recorder.destroy();
    for (openni::VideoStream& stream : streams) stream.destroy();
    device.close();
  }
  openni::OpenNI::shutdown();
  return ok;
}

// Records `frames` frames of the simulated device's infrared stream (HPOSE_SIM_DEPTH_AS_IR).
bool RecordInfrared(const std::string& oni, int frames) {
  ScopedEnv as_ir("HPOSE_SIM_DEPTH_AS_IR", "1");
  return RecordWithOpenni2(oni, frames, {openni::SENSOR_IR});
}

TEST_F(Openni2Test, ARecordingWithoutDepthIsRefusedAndClosedCleanly) {
  const std::string oni = *dir_ + "/infrared.oni";
  ASSERT_TRUE(RecordInfrared(oni, 3));
  ExpectPromptCloses([&](int i) {
    Openni2Source source(oni, AsFastAsRead());
    const Status opened = source.Open();
    ASSERT_FALSE(opened.ok()) << i;
    EXPECT_EQ(opened.error().code, ErrorCode::kDataLoss);
    EXPECT_NE(opened.error().message.find(oni + ": no depth stream (it has infrared only)"),
              std::string::npos)
        << opened.error().message;
  });
  // Re-recorded as a device (openni2://FILE.oni, as hpose record --device takes it).
  const std::string out = *dir_ + "/rerecorded.oni";
  ExpectPromptCloses([&](int i) {
    RecordOptions options;
    options.frames = 2;
    Result<RecordSummary> rec = RecordOpenni2("openni2://" + oni, out, options, nullptr);
    ASSERT_FALSE(rec.ok()) << i;
    EXPECT_NE(rec.error().message.find("no depth stream (it has infrared only)"), std::string::npos)
        << rec.error().message;
  });
  EXPECT_FALSE(std::filesystem::exists(out));
}

TEST_F(Openni2Test, ARecordingOfDepthAndInfraredPlaysItsDepth) {
  // As a PS1080's recordings hold depth beside colour or infrared: the depth stream alone is
  // read, every frame of it in order and once, as fast as read or at the recorded pace (then
  // no sooner than the recording's own span: OpenNI2's player at its own pace would replace
  // the last frame by the first of its next round before it is read).
  const std::string oni = *dir_ + "/depth_and_ir.oni";
  {
    ScopedEnv with_ir("HPOSE_SIM_DEPTH_WITH_IR", "1");
    ASSERT_TRUE(RecordWithOpenni2(oni, 5, {openni::SENSOR_DEPTH, openni::SENSOR_IR}));
  }
  for (const bool realtime : {false, true}) {
    SCOPED_TRACE(realtime ? "at the recorded pace" : "as fast as read");
    Openni2SourceOptions options;
    options.replay.realtime = realtime;
    Openni2Source source(oni, options);
    const Status opened = source.Open();
    ASSERT_TRUE(opened.ok()) << opened.error().ToString();
    ASSERT_GE(source.frame_count(), 5);
    long frames = 0;
    double first_time = -1.0;
    double last_time = -1.0;
    std::chrono::steady_clock::time_point first_read;
    while (true) {
      Result<Frame> f = source.Next();
      if (!f.ok()) {
        EXPECT_EQ(f.error().code, ErrorCode::kOutOfRange) << f.error().ToString();
        break;
      }
      ++frames;
      if (frames == 1) {
        first_read = std::chrono::steady_clock::now();
        first_time = f->source_time_s;
      }
      EXPECT_GE(MatchingFrame(f->depth), 0) << "frame " << frames;
      EXPECT_EQ(f->origin, oni + "#" + std::to_string(frames));
      EXPECT_GT(f->source_time_s, last_time);
      last_time = f->source_time_s;
      ASSERT_LE(frames, source.frame_count());
    }
    EXPECT_EQ(frames, source.frame_count());
    const double read_in_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - first_read).count();
    const double span_s = last_time - first_time;
    EXPECT_GT(span_s, 0.05);  // 30 frames a second, five frames.
    if (realtime) EXPECT_GE(read_in_s, span_s - 1e-3);
    EXPECT_LT(read_in_s, 10.0);
    source.Close();
  }
  // A reader slower than the recorded pace reads every frame all the same, later than they
  // were due, and the recording ends after its last: it is not read again from its start.
  Openni2SourceOptions realtime;
  realtime.replay.realtime = true;
  Openni2Source slow(oni, realtime);
  ASSERT_TRUE(slow.Open().ok());
  double last_time = -1.0;
  int frames = 0;
  for (;; ++frames) {
    Result<Frame> f = slow.Next();
    if (!f.ok()) {
      EXPECT_EQ(f.error().code, ErrorCode::kOutOfRange) << f.error().ToString();
      break;
    }
    EXPECT_GT(f->source_time_s, last_time) << "read again from the start";
    last_time = f->source_time_s;
    ASSERT_LE(frames, slow.frame_count());
    std::this_thread::sleep_for(std::chrono::milliseconds(70));
  }
  EXPECT_EQ(frames, slow.frame_count());
  slow.Close();
}

// The bytes of the file at `path` (empty when it cannot be read).
std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Three frames of the simulated device recorded to `oni` with OpenNI2's recorder.
bool RecordThreeFrames(const std::string& oni) {
  RecordOptions options;
  options.frames = 3;
  return RecordOpenni2("openni2://", oni, options, nullptr).ok();
}

TEST_F(Openni2Test, ATruncatedRecordingIsRefusedOrPlaysTheFramesItHolds) {
  // A recording cut short (a full disk, a copy interrupted), at points through the whole file:
  // OpenNI2 refuses it, named as a damaged recording, or it plays frames in order, no more than
  // it counts, and ends; never a hang, a crash or a frame twice.
  const std::string oni = *dir_ + "/whole.oni";
  ASSERT_TRUE(RecordThreeFrames(oni));
  const std::string bytes = FileBytes(oni);
  ASSERT_GT(bytes.size(), 1000u);
  const std::string cut_path = *dir_ + "/cut.oni";
  int refused = 0;
  int played = 0;
  for (size_t part = 0; part < 24; ++part) {
    const size_t cut = bytes.size() * part / 24;
    std::ofstream(cut_path, std::ios::binary | std::ios::trunc).write(bytes.data(), cut);
    Openni2SourceOptions source_options;
    source_options.replay.realtime = false;
    Openni2Source source(cut_path, source_options);
    Status opened = source.Open();
    if (!opened.ok()) {
      ++refused;
      EXPECT_EQ(opened.error().code, ErrorCode::kDataLoss) << cut;
      EXPECT_NE(opened.error().message.find(cut_path), std::string::npos) << cut;
      continue;
    }
    ++played;
    const long count = source.frame_count();
    EXPECT_GE(count, 1) << cut;
    std::vector<long> indices;  // OpenNI2's frame index, from the frame's origin "path#index".
    Result<Frame> frame = source.Next();
    for (; frame.ok() && indices.size() <= static_cast<size_t>(count); frame = source.Next()) {
      const long index = std::stol(frame->origin.substr(frame->origin.rfind('#') + 1));
      EXPECT_TRUE(indices.empty() || indices.back() < index) << cut;
      indices.push_back(index);
    }
    EXPECT_LE(indices.size(), static_cast<size_t>(count)) << cut;
    ASSERT_FALSE(frame.ok());
    EXPECT_TRUE(frame.error().code == ErrorCode::kOutOfRange ||
                frame.error().code == ErrorCode::kDataLoss)
        << cut << ": " << frame.error().ToString();
    source.Close();
  }
  // The cuts include an empty file and the recording less its last 1/24.
  EXPECT_GT(refused, 0);
  EXPECT_GT(played, 0);
}

// Byte offsets of the records of type `type` in an .oni: OpenNI's recording format starts each
// record with the magic "NIR\0", its type as a little-endian 32-bit word (3 an integer
// property, 10 a frame's data), and more of its header, 28 bytes in all.
constexpr std::uint32_t kIntPropertyRecord = 3;
constexpr std::uint32_t kNewDataRecord = 10;
constexpr size_t kRecordHeaderBytes = 28;

std::uint32_t LittleEndian32(const std::string& bytes, size_t at) {
  std::uint32_t v = 0;
  for (int b = 3; b >= 0; --b) v = (v << 8) | static_cast<unsigned char>(bytes[at + b]);
  return v;
}

std::vector<size_t> RecordOffsets(const std::string& bytes, std::uint32_t type) {
  const std::string magic("NIR\0", 4);
  std::vector<size_t> offsets;
  for (size_t at = bytes.find(magic); at != std::string::npos; at = bytes.find(magic, at + 1)) {
    if (at + kRecordHeaderBytes > bytes.size()) break;
    if (LittleEndian32(bytes, at + 4) == type) offsets.push_back(at);
  }
  return offsets;
}

TEST_F(Openni2Test, ARecordingThatCrashesOpenni2sFileDriverIsRefused) {
  // The first integer property's name with its last letter and its terminating zero replaced
  // by 0xFF (a damaged copy): OpenNI2's file driver dies of SIGSEGV opening such a file. The
  // source opens a recording in a child process first, so the crash is the child's and the
  // recording is refused by name.
  const std::string oni = *dir_ + "/whole_for_crash.oni";
  ASSERT_TRUE(RecordThreeFrames(oni));
  std::string bytes = FileBytes(oni);
  const std::vector<size_t> properties = RecordOffsets(bytes, kIntPropertyRecord);
  ASSERT_FALSE(properties.empty());
  const size_t name_at = properties[0] + kRecordHeaderBytes + 4;
  const size_t name_bytes = LittleEndian32(bytes, name_at - 4);
  ASSERT_GE(name_bytes, 2u);
  ASSERT_LT(name_at + name_bytes, bytes.size());
  ASSERT_EQ(bytes[name_at + name_bytes - 1], '\0') << "the name's terminating zero";
  bytes[name_at + name_bytes - 2] = '\xff';
  bytes[name_at + name_bytes - 1] = '\xff';
  const std::string damaged = *dir_ + "/crashing.oni";
  std::ofstream(damaged, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size());

  Openni2Source source(damaged, Openni2SourceOptions{});
  const Status opened = source.Open();
  ASSERT_FALSE(opened.ok());
  EXPECT_EQ(opened.error().code, ErrorCode::kDataLoss) << opened.error().ToString();
  EXPECT_NE(opened.error().message.find(damaged), std::string::npos);
  EXPECT_NE(opened.error().message.find("damaged recording: OpenNI2's file driver"),
            std::string::npos)
      << opened.error().message;
  // Given as the device (openni2://FILE.oni), to the source and to the recorder, it is
  // refused the same way, and the recorder writes nothing.
  Openni2Source as_device("openni2://" + damaged, Openni2SourceOptions{});
  const Status device_opened = as_device.Open();
  ASSERT_FALSE(device_opened.ok());
  EXPECT_EQ(device_opened.error().code, ErrorCode::kDataLoss);
  EXPECT_NE(device_opened.error().message.find("damaged recording: OpenNI2's file driver"),
            std::string::npos)
      << device_opened.error().message;
  for (const std::string out : {*dir_ + "/from_crashing.oni", *dir_ + "/from_crashing_png"}) {
    RecordOptions options;
    options.frames = 2;
    const Result<RecordSummary> rec = RecordOpenni2("openni2://" + damaged, out, options, nullptr);
    ASSERT_FALSE(rec.ok()) << out;
    EXPECT_EQ(rec.error().code, ErrorCode::kDataLoss) << rec.error().ToString();
    EXPECT_NE(rec.error().message.find(damaged), std::string::npos) << rec.error().message;
    EXPECT_FALSE(std::filesystem::exists(out)) << out;
  }
  // The undamaged recording still opens and plays.
  Openni2Source whole(oni, Openni2SourceOptions{});
  ASSERT_TRUE(whole.Open().ok());
  EXPECT_TRUE(whole.Next().ok());
  whole.Close();
}

TEST_F(Openni2Test, ARecordingWhosePlayerStallsEndsWithAnError) {
  // A frame record whose header is wiped (a damaged copy): OpenNI2's player then reads on and
  // never gives the frame, and a read waiting for it used to wait for ever (hposed's source
  // thread, `hpose replay`). The frames before it are read; the stalled one is a named error
  // within seconds, the next read ends the recording, and the source closes.
  const std::string oni = *dir_ + "/whole_for_stall.oni";
  ASSERT_TRUE(RecordThreeFrames(oni));
  std::string bytes = FileBytes(oni);
  const std::vector<size_t> records = RecordOffsets(bytes, kNewDataRecord);
  ASSERT_GE(records.size(), 3u) << "frame records found in the recording";
  std::fill_n(bytes.begin() + static_cast<std::ptrdiff_t>(records[1]), 8, '\0');
  const std::string damaged = *dir_ + "/stalled.oni";
  std::ofstream(damaged, std::ios::binary | std::ios::trunc).write(bytes.data(), bytes.size());

  Openni2SourceOptions source_options;
  source_options.replay.realtime = false;
  Openni2Source source(damaged, source_options);
  ASSERT_TRUE(source.Open().ok());
  Result<Frame> first = source.Next();
  ASSERT_TRUE(first.ok()) << first.error().ToString();
  const auto before = std::chrono::steady_clock::now();
  Result<Frame> stalled = source.Next();
  const double waited_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
  ASSERT_FALSE(stalled.ok());
  EXPECT_EQ(stalled.error().code, ErrorCode::kDataLoss) << stalled.error().ToString();
  EXPECT_NE(stalled.error().message.find(damaged), std::string::npos);
  EXPECT_NE(stalled.error().message.find("damaged recording"), std::string::npos)
      << stalled.error().message;
  EXPECT_LT(waited_s, 15.0);
  Result<Frame> after = source.Next();
  ASSERT_FALSE(after.ok());
  EXPECT_EQ(after.error().code, ErrorCode::kOutOfRange) << after.error().ToString();
  source.Close();
}

// Names in `dir` that are not `keep`: what a recording leaves behind besides its file.
std::vector<std::string> OtherFiles(const std::string& dir, const std::string& keep) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().filename() != keep) names.push_back(entry.path().filename().string());
  }
  return names;
}

// Records up to 20 frames to `output` from the simulated device, which unplugs after `frames`
// frames and stays away longer than the recording's frame wait (0.5 s).
Result<RecordSummary> RecordFromADeviceThatUnplugs(int frames, const std::string& output) {
  setenv("HPOSE_SIM_DEPTH_DISCONNECT_AFTER", std::to_string(frames).c_str(), 1);
  setenv("HPOSE_SIM_DEPTH_OFFLINE_MS", "3000", 1);
  RecordOptions options;
  options.frames = 20;
  options.frame_timeout_s = 0.5;
  Result<RecordSummary> rec = RecordOpenni2("openni2://", output, options, nullptr);
  unsetenv("HPOSE_SIM_DEPTH_DISCONNECT_AFTER");
  unsetenv("HPOSE_SIM_DEPTH_OFFLINE_MS");
  return rec;
}

TEST_F(Openni2Test, AFailedOniRecordingLeavesThePreviousFileAsItWas) {
  const std::string dir = *dir_ + "/kept";
  std::filesystem::create_directories(dir);
  const std::string oni = dir + "/take.oni";
  ASSERT_TRUE(WriteFileAtomically(oni, "an earlier take").ok());
  // The device opens, the recording starts, and no frame comes.
  Result<RecordSummary> rec = RecordFromADeviceThatUnplugs(0, oni);
  ASSERT_FALSE(rec.ok());
  EXPECT_EQ(rec.error().code, ErrorCode::kUnavailable);
  EXPECT_NE(rec.error().message.find("no frame for 500 ms"), std::string::npos)
      << rec.error().ToString();
  Result<std::string> kept = ReadFile(oni);
  ASSERT_TRUE(kept.ok());
  EXPECT_TRUE(*kept == "an earlier take")
      << "the earlier file was replaced: " << kept->size() << " bytes";
  EXPECT_TRUE(OtherFiles(dir, "take.oni").empty());
  // A directory that does not exist is named before any device opens.
  rec = RecordOpenni2("openni2://", dir + "/missing/take.oni", {}, nullptr);
  ASSERT_FALSE(rec.ok());
  EXPECT_NE(rec.error().message.find("missing"), std::string::npos) << rec.error().ToString();
}

TEST_F(Openni2Test, FramesRecordedBeforeTheDeviceStoppedAreKept) {
  const std::string dir = *dir_ + "/stalled";
  std::filesystem::create_directories(dir);
  const std::string oni = dir + "/take.oni";
  ASSERT_TRUE(WriteFileAtomically(oni, "an earlier take").ok());
  Result<RecordSummary> rec = RecordFromADeviceThatUnplugs(5, oni);
  ASSERT_FALSE(rec.ok());
  EXPECT_EQ(rec.error().code, ErrorCode::kUnavailable);
  EXPECT_NE(rec.error().message.find("no frame for 500 ms"), std::string::npos)
      << rec.error().ToString();
  EXPECT_NE(rec.error().message.find("the 5 frame(s) recorded before are in " + oni),
            std::string::npos)
      << rec.error().ToString();
  EXPECT_TRUE(OtherFiles(dir, "take.oni").empty());

  ReplayOptions replay;
  replay.realtime = false;
  Result<std::unique_ptr<FrameSource>> source = MakeFrameSource(oni, replay);
  ASSERT_TRUE(source.ok()) << source.error().ToString();
  ASSERT_TRUE((*source)->Open().ok());
  EXPECT_EQ((*source)->frame_count(), 5);
  (*source)->Close();

  // A directory of PNG frames keeps its frames too.
  rec = RecordFromADeviceThatUnplugs(3, dir + "/frames");
  ASSERT_FALSE(rec.ok());
  EXPECT_EQ(rec.error().code, ErrorCode::kUnavailable) << rec.error().ToString();
  // At most the 3 frames sent (one may be missed while a frame is written), all named.
  const long pngs = static_cast<long>(OtherFiles(dir + "/frames", "intrinsics.json").size());
  EXPECT_GE(pngs, 1);
  EXPECT_LE(pngs, 3);
  EXPECT_NE(rec.error().message.find("the " + std::to_string(pngs) +
                                     " frame(s) recorded before are in " + dir + "/frames"),
            std::string::npos)
      << rec.error().ToString();
}

TEST_F(Openni2Test, RecordsAPngDirectoryThatReplays) {
  const std::string out_dir = *dir_ + "/recorded";
  RecordOptions options;
  options.frames = 3;
  Result<RecordSummary> rec = RecordOpenni2("openni2://", out_dir, options, nullptr);
  ASSERT_TRUE(rec.ok()) << rec.error().ToString();
  EXPECT_EQ(rec->format, "png-dir");
  ASSERT_TRUE(std::filesystem::exists(out_dir + "/intrinsics.json"));
  Result<DepthImage> first = ReadDepthPng(out_dir + "/frame_000000.png");
  ASSERT_TRUE(first.ok());
  EXPECT_GE(MatchingFrame(*first), 0);

  std::string csv;
  ASSERT_EQ(tu::RunCommand(tu::HposeProgram() + " replay '" + out_dir +
                               "' --format csv --no-progress --template " +
                               tu::TemplatePath("standing") + " 2>/dev/null",
                           &csv),
            0);
  std::istringstream lines(csv);
  std::string line;
  std::vector<std::string> rows;
  while (std::getline(lines, line)) rows.push_back(line);
  ASSERT_EQ(rows.size(), 4u);  // header + 3 frames.
  EXPECT_EQ(rows[0].rfind("sequence,source_time_s,", 0), 0u);
  for (size_t i = 1; i < rows.size(); ++i) {
    EXPECT_NE(rows[i].find(",standing,"), std::string::npos) << rows[i];
  }

  // Recording into it again is refused: the new frames would lie among the old ones.
  const auto written = std::filesystem::last_write_time(out_dir + "/frame_000000.png");
  options.frames = 1;
  rec = RecordOpenni2("openni2://", out_dir, options, nullptr);
  ASSERT_FALSE(rec.ok());
  EXPECT_EQ(rec.error().code, ErrorCode::kInvalidArgument);
  EXPECT_NE(rec.error().message.find("already holds a recording"), std::string::npos)
      << rec.error().ToString();
  EXPECT_EQ(std::filesystem::last_write_time(out_dir + "/frame_000000.png"), written);
}

// The window (u0, v0, w, h) of `image`, its rows reversed if `mirrored`.
DepthImage Window(const DepthImage& image, int u0, int v0, int w, int h, bool mirrored) {
  DepthImage out(w, h);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) out.at(u, v) = image.at(u0 + (mirrored ? w - 1 - u : u), v0 + v);
  }
  return out;
}

// The first frame that OpenNI2 itself delivers from `uri`, as the stream has it.
DepthImage RawFirstFrame(const std::string& uri, bool* mirrored) {
  DepthImage out;
  if (openni::OpenNI::initialize() != openni::STATUS_OK) return out;
  {
    openni::Device device;
    openni::VideoStream depth;
    if (device.open(uri.c_str()) == openni::STATUS_OK &&
        depth.create(device, openni::SENSOR_DEPTH) == openni::STATUS_OK &&
        depth.start() == openni::STATUS_OK) {
      *mirrored = depth.getMirroringEnabled();
      openni::VideoFrameRef ref;
      if (depth.readFrame(&ref) == openni::STATUS_OK) {
        out = DepthImage(ref.getWidth(), ref.getHeight());
        const auto* base = static_cast<const std::uint8_t*>(ref.getData());
        for (int v = 0; v < out.height; ++v) {
          const auto* row =
              reinterpret_cast<const openni::DepthPixel*>(base + v * ref.getStrideInBytes());
          for (int u = 0; u < out.width; ++u) out.at(u, v) = row[u];
        }
      }
      depth.stop();
      depth.destroy();
    }
    device.close();
  }
  openni::OpenNI::shutdown();
  return out;
}

// The first frame of `spec` through an Openni2Source, opened and closed (and destroyed: a live
// source holds OpenNI2, its drivers loaded, until then).
Result<Frame> FirstFrame(const std::string& spec, const Openni2SourceOptions& options) {
  Openni2Source source(spec, options);
  const Status opened = source.Open();
  if (!opened.ok()) return opened.error();
  Result<Frame> frame = source.Next();
  source.Close();
  return frame;
}

TEST_F(Openni2Test, AMirroredStreamIsReadInTheSensorsOwnColumns) {
  // A PS1080 configured to mirror (Mirror=1) reverses every row: read as it comes, the robot
  // would stand mirrored, its heading and sideways position negated. The device is asked to
  // stop mirroring; a recording made while it mirrored is reversed back frame by frame.
  ScopedEnv mirrored("HPOSE_SIM_DEPTH_MIRRORED", "1");
  bool raw_mirrored = false;
  const DepthImage raw = RawFirstFrame("hpose-sim://depth0", &raw_mirrored);
  ASSERT_TRUE(raw_mirrored);
  ASSERT_EQ(raw.width, 320);
  ASSERT_EQ(MatchingFrame(raw), -1) << "the device does not mirror";
  bool matched = false;
  for (int i = 0; i < 3; ++i) matched |= Window(Png(i), 0, 0, 320, 240, true).mm == raw.mm;
  ASSERT_TRUE(matched) << "the device's frame is no mirrored PNG";

  // A device that stops mirroring when asked, and one that will not (reversed here instead).
  for (const char* mode : {"1", "fixed"}) {
    ScopedEnv how("HPOSE_SIM_DEPTH_MIRRORED", mode);
    Openni2Source live("openni2://", Openni2SourceOptions{});
    ASSERT_TRUE(live.Open().ok());
    for (int i = 0; i < 3; ++i) {
      Result<Frame> f = live.Next();
      ASSERT_TRUE(f.ok()) << f.error().ToString();
      EXPECT_GE(MatchingFrame(f->depth), 0) << mode << ": live frame " << i << " is mirrored";
    }
  }

  const std::string oni = *dir_ + "/mirrored.oni";
  RecordOptions options;
  options.frames = 3;
  Result<RecordSummary> rec = RecordOpenni2("openni2://", oni, options, nullptr);
  ASSERT_TRUE(rec.ok()) << rec.error().ToString();
  bool file_mirrored = false;
  const DepthImage recorded = RawFirstFrame(oni, &file_mirrored);
  EXPECT_TRUE(file_mirrored) << "OpenNI2's recorder kept no mirroring flag";
  EXPECT_EQ(MatchingFrame(recorded), -1) << "the recording is not mirrored";
  Openni2Source played(oni, AsFastAsRead());
  ASSERT_TRUE(played.Open().ok());
  for (int i = 0; i < rec->frames; ++i) {
    Result<Frame> f = played.Next();
    ASSERT_TRUE(f.ok()) << f.error().ToString();
    EXPECT_GE(MatchingFrame(f->depth), 0) << "played frame " << i << " is still mirrored";
  }
  played.Close();
}

TEST_F(Openni2Test, DepthRegisteredToColourIsSwitchedOff) {
  // PS1080's Registration=1 draws depth from the colour camera's place (here: 8 pixels to the
  // right), whose focal length is not the depth field of view OpenNI2 reports. Live and
  // recorded, hpose switches it off and takes the depth camera's own image.
  ScopedEnv registered("HPOSE_SIM_DEPTH_REGISTERED", "1");
  bool mirrored = true;
  const DepthImage raw = RawFirstFrame("hpose-sim://depth0", &mirrored);
  ASSERT_EQ(raw.width, 320);
  ASSERT_EQ(MatchingFrame(raw), -1) << "the device does not register";

  Result<Frame> f = FirstFrame("openni2://", Openni2SourceOptions{});
  ASSERT_TRUE(f.ok()) << f.error().ToString();
  EXPECT_GE(MatchingFrame(f->depth), 0) << "the live frame is still registered";

  const std::string oni = *dir_ + "/unregistered.oni";
  RecordOptions options;
  options.frames = 2;
  ASSERT_TRUE(RecordOpenni2("openni2://", oni, options, nullptr).ok());
  EXPECT_GE(MatchingFrame(RawFirstFrame(oni, &mirrored)), 0) << "the recording is registered";
}

TEST_F(Openni2Test, DepthInTenthsOfAMillimetreIsRoundedToTheNearestMillimetre) {
  // A stream in 100 um units (the PNGs' values served as such): each pixel is the nearest
  // millimetre, not the one below (which would bring every point 0.45 mm nearer on average).
  ScopedEnv units("HPOSE_SIM_DEPTH_100_UM", "1");
  Result<Frame> f = FirstFrame("openni2://", Openni2SourceOptions{});
  ASSERT_TRUE(f.ok()) << f.error().ToString();
  int match = -1;
  int rounded_up = 0;
  for (int p = 0; p < 3; ++p) {
    const DepthImage png = Png(p);
    DepthImage expected(png.width, png.height);
    for (size_t i = 0; i < png.mm.size(); ++i) {
      expected.mm[i] = static_cast<std::uint16_t>((png.mm[i] + 5) / 10);
    }
    if (expected.mm == f->depth.mm) {
      match = p;
      for (size_t i = 0; i < png.mm.size(); ++i) rounded_up += png.mm[i] % 10 >= 5 ? 1 : 0;
    }
  }
  ASSERT_GE(match, 0) << "no frame is the PNG's values rounded to millimetres";
  EXPECT_GT(rounded_up, 1000) << "too few pixels tell rounding from truncation";
}

TEST_F(Openni2Test, ACroppedStreamKeepsEachPixelsRay) {
  // A device cropped to a window (PS1080's Depth.Cropping) sends that window alone: its pixels
  // keep the rays they have in the whole image, the principal point moved by the window's
  // origin; mirrored as well, the window is reversed back.
  Result<Frame> full = FirstFrame("openni2://", Openni2SourceOptions{});
  ASSERT_TRUE(full.ok()) << full.error().ToString();
  const Intrinsics k = full->intrinsics;

  ScopedEnv crop("HPOSE_SIM_DEPTH_CROP", "40,30,200,150");
  for (const bool mirror : {false, true}) {
    ScopedEnv mirrored("HPOSE_SIM_DEPTH_MIRRORED", mirror ? "1" : "0");
    const std::string oni = *dir_ + (mirror ? "/cropped_mirrored.oni" : "/cropped.oni");
    RecordOptions options;
    options.frames = 3;
    Result<RecordSummary> rec = RecordOpenni2("openni2://", oni, options, nullptr);
    ASSERT_TRUE(rec.ok()) << rec.error().ToString();
    for (const std::string& spec : {std::string("openni2://"), oni}) {
      SCOPED_TRACE(spec + (mirror ? ", mirrored" : ""));
      Openni2Source source(spec, spec == oni ? AsFastAsRead() : Openni2SourceOptions{});
      ASSERT_TRUE(source.Open().ok());
      for (int i = 0; i < 3; ++i) {
        Result<Frame> f = source.Next();
        ASSERT_TRUE(f.ok()) << f.error().ToString();
        ASSERT_EQ(f->depth.width, 200);
        ASSERT_EQ(f->depth.height, 150);
        int match = -1;
        for (int p = 0; p < 3; ++p) {
          if (Window(Png(p), 40, 30, 200, 150, false).mm == f->depth.mm) match = p;
        }
        EXPECT_GE(match, 0) << "frame " << i << " is no window of a PNG in the sensor's columns";
        EXPECT_NEAR(f->intrinsics.fx, k.fx, 1e-9);
        EXPECT_NEAR(f->intrinsics.fy, k.fy, 1e-9);
        EXPECT_NEAR(f->intrinsics.cx, k.cx - 40.0, 1e-9);
        EXPECT_NEAR(f->intrinsics.cy, k.cy - 30.0, 1e-9);
        EXPECT_EQ(f->intrinsics.width, 200);
        EXPECT_EQ(f->intrinsics.height, 150);
      }
      source.Close();
    }
  }

  // A calibrated camera's intrinsics are given for the whole image and moved the same way.
  Openni2SourceOptions calibrated = AsFastAsRead();
  calibrated.replay.has_intrinsics = true;
  calibrated.replay.intrinsics = k;
  calibrated.replay.intrinsics.cx = 161.5;
  Result<Frame> f = FirstFrame(*dir_ + "/cropped.oni", calibrated);
  ASSERT_TRUE(f.ok()) << f.error().ToString();
  EXPECT_NEAR(f->intrinsics.cx, 121.5, 1e-9);
  EXPECT_NEAR(f->intrinsics.cy, k.cy - 30.0, 1e-9);

  // A small window in the image's far corner: the principal point lies far before its first
  // column and row, and its pixels still keep their rays.
  const int u0 = k.width - 40, v0 = k.height - 30;
  ScopedEnv corner("HPOSE_SIM_DEPTH_CROP",
                   std::to_string(u0) + "," + std::to_string(v0) + ",40,30");
  Result<Frame> c = FirstFrame("openni2://", Openni2SourceOptions{});
  ASSERT_TRUE(c.ok()) << c.error().ToString();
  ASSERT_EQ(c->depth.width, 40);
  ASSERT_EQ(c->depth.height, 30);
  EXPECT_NEAR(c->intrinsics.cx, k.cx - u0, 1e-9);
  EXPECT_NEAR(c->intrinsics.cy, k.cy - v0, 1e-9);
  EXPECT_LT(c->intrinsics.cx, -40.0) << "the window is not off the image's centre";
  bool is_window = false;
  for (int p = 0; p < 3; ++p) is_window |= Window(Png(p), u0, v0, 40, 30, false).mm == c->depth.mm;
  EXPECT_TRUE(is_window) << "the corner frame is no window of a PNG in the sensor's columns";
}

TEST(PreferredDepthModeTest, TheKinectsImageAtItsFrameRateInMillimetres) {
  auto mode = [](int w, int h, int fps, const char* units) {
    Openni2DepthMode m;
    m.width = w;
    m.height = h;
    m.fps = fps;
    m.units = units;
    return m;
  };
  // PS1080's list starts at 320x240; the 640x480 mode at 30 fps in millimetres is taken.
  const std::vector<Openni2DepthMode> ps1080 = {mode(320, 240, 30, "1 mm"),
                                                mode(320, 240, 60, "1 mm"),
                                                mode(640, 480, 30, "100 um"),
                                                mode(640, 480, 30, "1 mm"),
                                                mode(160, 120, 30, "1 mm"),
                                                mode(1280, 1024, 30, "1 mm"),
                                                mode(640, 480, 30, "pixel format 103")};
  EXPECT_EQ(PreferredDepthMode(ps1080), 3);
  // Given intrinsics of 320x240: that size, at its highest frame rate.
  EXPECT_EQ(PreferredDepthMode(ps1080, 320, 240), 1);
  // A size no mode has: as without.
  EXPECT_EQ(PreferredDepthMode(ps1080, 800, 600), 3);
  // 30 frames a second before more pixels; tenths of a millimetre when nothing else.
  EXPECT_EQ(PreferredDepthMode({mode(640, 480, 15, "1 mm"), mode(320, 240, 30, "1 mm")}), 1);
  EXPECT_EQ(PreferredDepthMode({mode(320, 240, 30, "100 um"), mode(640, 480, 30, "100 um")}), 1);
  // Wider than a Kinect's image only when nothing else, and then the smallest.
  EXPECT_EQ(PreferredDepthMode({mode(1280, 1024, 30, "1 mm"), mode(640, 480, 30, "1 mm")}), 1);
  EXPECT_EQ(PreferredDepthMode({mode(1920, 1080, 30, "1 mm"), mode(1280, 1024, 30, "1 mm")}), 1);
  // Nothing in depth units (shift values): none.
  EXPECT_EQ(PreferredDepthMode({mode(640, 480, 30, "pixel format 103")}), -1);
  EXPECT_EQ(PreferredDepthMode({}), -1);
}

TEST_F(Openni2Test, ADeviceStartingAtHalfSizeIsStreamedAtItsFullSize) {
  // As PS1080's driver starts in 320x240 of its 640x480: live, recorded and listed, hpose
  // takes the full-size mode; with intrinsics of the half size given, the half.
  ScopedEnv modes("HPOSE_SIM_DEPTH_MODES", "several");
  Result<Frame> f = FirstFrame("openni2://", Openni2SourceOptions{});
  ASSERT_TRUE(f.ok()) << f.error().ToString();
  EXPECT_EQ(f->depth.width, 320);
  EXPECT_GE(MatchingFrame(f->depth), 0);

  const std::string oni = *dir_ + "/full_size.oni";
  RecordOptions options;
  options.frames = 2;
  ASSERT_TRUE(RecordOpenni2("openni2://", oni, options, nullptr).ok());
  bool mirrored = true;
  const DepthImage recorded = RawFirstFrame(oni, &mirrored);
  EXPECT_EQ(recorded.width, 320);
  EXPECT_GE(MatchingFrame(recorded), 0);

  Openni2SourceOptions half;
  half.replay.has_intrinsics = true;
  Result<Intrinsics> k = ReadIntrinsicsJson(*dir_ + "/frames/intrinsics.json");
  ASSERT_TRUE(k.ok());
  half.replay.intrinsics = *k;
  half.replay.intrinsics.width /= 2;
  half.replay.intrinsics.height /= 2;
  half.replay.intrinsics.fx /= 2;
  half.replay.intrinsics.fy /= 2;
  half.replay.intrinsics.cx /= 2;
  half.replay.intrinsics.cy /= 2;
  f = FirstFrame("openni2://", half);
  ASSERT_TRUE(f.ok()) << f.error().ToString();
  ASSERT_EQ(f->depth.width, 160);
  bool decimated = false;
  for (int p = 0; p < 3; ++p) {
    const DepthImage png = Png(p);
    DepthImage every_second(160, 120);
    for (int v = 0; v < 120; ++v) {
      for (int u = 0; u < 160; ++u) every_second.at(u, v) = png.at(2 * u, 2 * v);
    }
    decimated |= every_second.mm == f->depth.mm;
  }
  EXPECT_TRUE(decimated);

  std::string out;
  ASSERT_EQ(tu::RunCommand(tu::HposeProgram() + " record --list-devices", &out), 0) << out;
  EXPECT_NE(out.find("    160x120 at 30 fps in 1 mm  (the device starts in it)\n"
                     "    320x240 at 30 fps in 1 mm  (hpose streams in it)\n"),
            std::string::npos)
      << out;
}

TEST_F(Openni2Test, HposedLogsTheCameraItStreams) {
  // The mode hposed took, and the camera it derived, in its log for a person to check.
  ScopedEnv modes("HPOSE_SIM_DEPTH_MODES", "several");
  tu::HposedProcess hposed({"--source", "openni2://", "--listen", "127.0.0.1:0"});
  ASSERT_FALSE(hposed.address().empty());
  // The device reports the field of view of its frames' intrinsics; the principal point is
  // taken at the image centre.
  Result<Intrinsics> k = ReadIntrinsicsJson(*dir_ + "/frames/intrinsics.json");
  ASSERT_TRUE(k.ok());
  char line[160];
  std::snprintf(line, sizeof(line),
                "source openni2://: 320x240 depth frames, fx %.1f fy %.1f cx 160.0 cy 120.0", k->fx,
                k->fy);
  const std::string expected = line;
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::seconds(60 * hpose::testing::kTimeScale);
  while (hposed.output().find(expected) == std::string::npos &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const std::string log = hposed.output();
  EXPECT_NE(log.find(expected), std::string::npos) << log.substr(0, 3000);
  // Once: the camera does not change from frame to frame.
  EXPECT_EQ(log.find("depth frames", log.find(expected) + expected.size()), std::string::npos)
      << log.substr(0, 3000);
  // GetStatus gives it too (hpose query status).
  std::string status;
  ASSERT_EQ(
      tu::RunCommand(tu::HposeProgram() + " query status --server " + hposed.address(), &status), 0)
      << status;
  const std::string camera_line = "camera: " + expected.substr(expected.find(": ") + 2) + "\n";
  EXPECT_NE(status.find(camera_line), std::string::npos) << camera_line << "not in:\n" << status;

  // A recording of point clouds has no camera to show: it says so.
  const std::string clouds = *dir_ + "/clouds";
  ASSERT_TRUE(tu::SimulateFrames(*dir_ + "/with_clouds", 2, "", /*clouds=*/true));
  std::filesystem::create_directories(clouds);
  for (const char* name : {"cloud_000.pcd", "cloud_001.pcd"}) {
    std::filesystem::rename(*dir_ + "/with_clouds/" + name, clouds + "/" + name);
  }
  tu::HposedProcess cloud_hposed({"--source", clouds, "--listen", "127.0.0.1:0"});
  ASSERT_FALSE(cloud_hposed.address().empty());
  const std::string cloud_line = "source " + clouds + ": point clouds in the sensor frame";
  while (cloud_hposed.output().find(cloud_line) == std::string::npos &&
         std::chrono::steady_clock::now() < deadline + std::chrono::seconds(60)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  EXPECT_NE(cloud_hposed.output().find(cloud_line), std::string::npos)
      << cloud_hposed.output().substr(0, 3000);
  status.clear();
  ASSERT_EQ(tu::RunCommand(tu::HposeProgram() + " query status --server " + cloud_hposed.address(),
                           &status),
            0)
      << status;
  EXPECT_NE(status.find("camera: none, point clouds in the sensor frame\n"), std::string::npos)
      << status;
}

TEST_F(Openni2Test, RecordListsTheDevicesOpenni2Sees) {
  std::string out;
  {
    ScopedEnv mirrored("HPOSE_SIM_DEPTH_MIRRORED", "1");
    ScopedEnv crop("HPOSE_SIM_DEPTH_CROP", "0,0,320,200");
    ASSERT_EQ(tu::RunCommand(tu::HposeProgram() + " record --list-devices", &out), 0) << out;
  }
  for (const char* expected :
       {"openni2://hpose-sim://depth0\n", "simulated depth camera (hpose), USB 0000:0000",
        "mirrored (hpose reads it unmirrored)", "cropped (hpose keeps each pixel's ray)",
        "    320x240 at 30 fps in 1 mm  (the device starts in it)  (hpose streams in it)\n"}) {
    EXPECT_NE(out.find(expected), std::string::npos) << expected << " not in:\n" << out;
  }
  // The simulated device reports the field of view of its frames' intrinsics.
  Result<Intrinsics> k = ReadIntrinsicsJson(*dir_ + "/frames/intrinsics.json");
  ASSERT_TRUE(k.ok());
  const double hfov_deg = 2.0 * std::atan(k->width / (2.0 * k->fx)) * 180.0 / M_PI;
  char fov[32];
  std::snprintf(fov, sizeof(fov), "field of view %.1f x", hfov_deg);
  EXPECT_NE(out.find(fov), std::string::npos) << fov << " not in:\n" << out;

  // Nothing plugged in: exit 5, and what may be missing.
  ScopedEnv unplugged("HPOSE_SIM_DEPTH_UNPLUGGED_FILE", *dir_ + "/frames/intrinsics.json");
  std::string err;
  EXPECT_EQ(tu::RunCommand(tu::HposeProgram() + " record --list-devices 2>&1", &err), 5) << err;
  EXPECT_NE(err.find("no OpenNI2 device found"), std::string::npos) << err;
  EXPECT_NE(err.find("libfreenect's OpenNI2 driver"), std::string::npos) << err;
  err.clear();
  EXPECT_EQ(tu::RunCommand(tu::HposeProgram() + " record --out " + *dir_ + "/none.oni 2>&1", &err),
            5)
      << err;
  EXPECT_NE(err.find("no OpenNI2 device found (`hpose record --list-devices`"), std::string::npos)
      << err;
  EXPECT_FALSE(std::filesystem::exists(*dir_ + "/none.oni"));
}

TEST_F(Openni2Test, RecordingFromANonDeviceIsRejected) {
  Result<RecordSummary> rec = RecordOpenni2(*dir_ + "/frames", *dir_ + "/x.oni", {}, nullptr);
  ASSERT_FALSE(rec.ok());
  EXPECT_EQ(rec.error().code, ErrorCode::kInvalidArgument);
  // A frame wait OpenNI2's integer milliseconds cannot hold is refused before any device opens.
  RecordOptions forever;
  forever.frame_timeout_s = 1e300;
  rec = RecordOpenni2("openni2://", *dir_ + "/x.oni", forever, nullptr);
  ASSERT_FALSE(rec.ok());
  EXPECT_NE(rec.error().message.find("frame timeout"), std::string::npos) << rec.error().message;
  EXPECT_FALSE(std::filesystem::exists(*dir_ + "/x.oni"));
}

}  // namespace
}  // namespace hpose::server
