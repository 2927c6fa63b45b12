// hpose's reader of OpenCV FileStorage text files against OpenCV's own parser as the
// reference: files OpenCV writes, and the FileStorage files shipped with OpenCV's examples.
#include "core/io/storage_reader.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace hpose {
namespace {

std::string TempPath(const std::string& name) {
  return testing::TempDir() + "/storage_" + std::to_string(::getpid()) + "_" + name;
}

// Compares a node of ours with OpenCV's, recursively; returns the number of nodes compared.
int ExpectSame(const cv::FileNode& ref, const StorageNode& ours, const std::string& where) {
  int compared = 1;
  if (ref.isMap()) {
    EXPECT_TRUE(ours.IsMap()) << where;
    if (!ours.IsMap()) return compared;
    std::size_t named = 0;
    for (const cv::FileNode& child : ref) {
      const std::string name = child.name();
      const StorageNode* mine = ours.Find(name);
      EXPECT_NE(mine, nullptr) << where << "/" << name;
      if (mine != nullptr) compared += ExpectSame(child, *mine, where + "/" + name);
      ++named;
    }
    // OpenCV keeps JSON's "type_id" member out of the map; it is a member here.
    const std::size_t extra = ours.Find("type_id") != nullptr && ref["type_id"].empty() ? 1 : 0;
    EXPECT_EQ(ours.members.size(), named + extra) << where;
  } else if (ref.isSeq()) {
    EXPECT_TRUE(ours.IsSeq()) << where;
    if (!ours.IsSeq()) return compared;
    EXPECT_EQ(ours.items.size(), ref.size()) << where;
    for (std::size_t i = 0; i < std::min(ours.items.size(), ref.size()); ++i) {
      compared += ExpectSame(ref[static_cast<int>(i)], ours.items[i],
                             where + "[" + std::to_string(i) + "]");
    }
  } else if (ref.isInt()) {
    long long v = 0;
    EXPECT_TRUE(ours.AsInt(&v)) << where << " = \"" << ours.text << "\"";
    EXPECT_EQ(v, static_cast<int>(ref)) << where;
  } else if (ref.isReal()) {
    double v = 0;
    EXPECT_TRUE(ours.AsNumber(&v)) << where << " = \"" << ours.text << "\"";
    const double expected = static_cast<double>(ref);
    if (std::isnan(expected)) {
      EXPECT_TRUE(std::isnan(v)) << where;
    } else {
      EXPECT_EQ(v, expected) << where;
    }
  } else if (ref.isString()) {
    EXPECT_TRUE(ours.IsString()) << where << " = \"" << ours.text << "\"";
    EXPECT_EQ(ours.text, static_cast<std::string>(ref)) << where;
  } else {
    EXPECT_EQ(ours.kind, StorageNode::Kind::kNone) << where;
  }
  return compared;
}

TEST(StorageReaderTest, ReadsWhatOpenCvWritesInYamlXmlAndJson) {
  for (const char* ext : {".yaml", ".xml", ".json"}) {
    const std::string path = TempPath(std::string("written") + ext);
    {
      cv::FileStorage fs(path, cv::FileStorage::WRITE);
      ASSERT_TRUE(fs.isOpened()) << path;
      fs << "image_width" << 640 << "negative" << -12;
      fs << "M1" << (cv::Mat_<double>(3, 3) << 443.405, 0, 258.6, 0, 277.128, 117.2, 0, 0, 1);
      fs << "T" << (cv::Mat_<double>(3, 1) << -0.09, 1e-3, 1e-20);
      fs << "F"
         << (cv::Mat_<float>(1, 3) << 0.5f, std::numeric_limits<float>::quiet_NaN(),
             -std::numeric_limits<float>::infinity());
      fs << "I" << (cv::Mat_<int>(2, 2) << 1, -2, 3, 4);
      fs << "imageSize" << std::vector<int>{640, 480};
      fs << "v" << std::vector<double>{1.5, 2, -3.25e-7};
      fs << "unit"
         << "mm";
      fs << "words"
         << "x y";
      fs << "real" << 3.25;
      fs << "nested"
         << "{"
         << "a" << 1 << "b"
         << "two words"
         << "inner"
         << "{"
         << "c" << 2.5 << "}"
         << "}";
      fs << "list"
         << "[" << 1 << "two" << 3.5 << "]";
      fs << "maps"
         << "["
         << "{"
         << "k" << 1 << "}"
         << "{"
         << "k" << 2 << "}"
         << "]";
    }
    cv::FileStorage ref(path, cv::FileStorage::READ);
    ASSERT_TRUE(ref.isOpened()) << path;
    Result<StorageNode> ours = ReadStorageFile(path, 1 << 20);
    ASSERT_TRUE(ours.ok()) << ours.error().ToString();
    ASSERT_TRUE(ours->IsMap());
    EXPECT_GT(ExpectSame(ref.root(), *ours, ext), 40) << ext;
    // The matrix reader gives the values OpenCV gives.
    cv::Mat m1;
    ref["M1"] >> m1;
    Result<Eigen::MatrixXd> mine = StorageMatrix(*ours->Find("M1"), path, "M1", 64);
    ASSERT_TRUE(mine.ok()) << mine.error().ToString();
    ASSERT_EQ(mine->rows(), 3);
    ASSERT_EQ(mine->cols(), 3);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) EXPECT_EQ((*mine)(r, c), m1.at<double>(r, c)) << ext;
    EXPECT_EQ(ours->Find("M1")->type_id, "opencv-matrix") << ext;
    Result<Eigen::MatrixXd> f = StorageMatrix(*ours->Find("F"), path, "F", 64);
    ASSERT_TRUE(f.ok());
    EXPECT_EQ((*f)(0, 0), 0.5);
    EXPECT_TRUE(std::isnan((*f)(0, 1)));
    EXPECT_EQ((*f)(0, 2), -std::numeric_limits<double>::infinity());
    std::filesystem::remove(path);
  }
}

// Every FileStorage file shipped with OpenCV's examples (opencv-doc) that OpenCV itself opens:
// calibrations, ArUco parameters, classifiers, a 550 kB model.
TEST(StorageReaderTest, ReadsOpenCvExampleFilesAsOpenCvDoes) {
  const std::filesystem::path examples = "/usr/share/doc/opencv-doc/examples";
  if (!std::filesystem::is_directory(examples)) {
    GTEST_SKIP() << examples << " is absent (Debian package opencv-doc)";
  }
  int files = 0, nodes = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(examples)) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || entry.file_size() > (1u << 20) ||
        (ext != ".yml" && ext != ".yaml" && ext != ".xml" && ext != ".json")) {
      continue;
    }
    const std::string path = entry.path().string();
    std::string head(64, '\0');
    std::ifstream(path).read(head.data(), 64);
    if (head.find("opencv_storage") == std::string::npos && head.find("%YAML") != 0) continue;
    cv::FileStorage ref;
    try {
      if (!ref.open(path, cv::FileStorage::READ)) continue;
    } catch (const cv::Exception&) {
      continue;
    }
    Result<StorageNode> ours = ReadStorageFile(path, 1 << 20);
    ASSERT_TRUE(ours.ok()) << ours.error().ToString();
    nodes += ExpectSame(ref.root(), *ours, path);
    ++files;
  }
  std::cout << files << " example files, " << nodes << " nodes compared\n";
  EXPECT_GE(files, 10);
}

// Each malformed text is an error naming the line, and none takes long or goes deep.
TEST(StorageReaderTest, MalformedTextIsAnErrorNamingTheLine) {
  struct Case {
    const char* text;
    int line;
    const char* says;
  };
  const Case cases[] = {
      {"%YAML:1.0\na: 1\n%TAG x\n", 3, "directive"},
      {"%YAML:1.0\na: [1, 2\n  # a comment\n", 2, "never closed"},
      {"%YAML:1.0\na: [1, 2\nb: 3\n", 3, "expected \",\" or \"]\""},
      {"a: 1\n  b: 2\n", 2, "indentation"},
      {"a:\n  - 1\n  b: 2\n", 3, "indentation"},
      {"a:\n  - 1\n  - 2\n - 3\n", 4, "indentation"},
      {"a: 1\n\tb: 2\n", 2, "tab"},
      {"a: \"open\nb: 2\n", 1, "never ends"},
      {"a: 1\na: 2\n", 1, "twice"},
      {"a: b: c\n", 1, "same line"},
      {"a: [1, 2] x\n", 1, "after a value"},
      {"a: {b 1}\n", 1, "\":\""},
      {"a: &x 1\n", 1, "anchors"},
      {"a: |\n  text\n", 1, "block scalars"},
      {"---\na: 1\n---\nb: 2\n", 4, "more than one"},
      {"<?xml version=\"1.0\"?>\n<opencv_storage>\n<a>1</b>\n</opencv_storage>\n", 3, "closes"},
      {"<?xml version=\"1.0\"?>\n<root><a>1</a></root>\n", 2, "opencv_storage"},
      {"<opencv_storage>\n<a>1\n", 2, "never closed"},
      {"<opencv_storage><a>x &bogus; y</a></opencv_storage>", 1, "entity"},
      {"<opencv_storage><a>1<b>2</b></a></opencv_storage>", 1, "mixes text"},
      {"<opencv_storage><a t=1>1</a></opencv_storage>", 1, "unquoted"},
      {"{\"a\": 1,\n \"b\" 2}", 2, "\":\""},
  };
  for (const Case& c : cases) {
    Result<StorageNode> r = ParseStorageText(c.text, "f.yml");
    ASSERT_FALSE(r.ok()) << c.text;
    EXPECT_EQ(r.error().code, ErrorCode::kDataLoss) << c.text;
    EXPECT_NE(r.error().message.find("f.yml: line " + std::to_string(c.line) + ":"),
              std::string::npos)
        << c.text << " -> " << r.error().message;
    EXPECT_NE(r.error().message.find(c.says), std::string::npos)
        << c.text << " -> " << r.error().message;
  }
  // Nesting beyond the limit, in every syntax.
  const int deep = kMaxStorageDepth + 5;
  std::string flow(deep, '['), xml = "<opencv_storage>", block;
  flow += std::string(deep, ']');
  for (int i = 0; i < deep; ++i) {
    xml += "<a>";
    block += std::string(2 * i, ' ') + "k:\n";
  }
  block += std::string(2 * deep, ' ') + "k: 1\n";
  for (const std::string& text : {flow, xml, block}) {
    Result<StorageNode> r = ParseStorageText(text, "deep");
    ASSERT_FALSE(r.ok()) << text.substr(0, 40);
    EXPECT_NE(r.error().message.find("nested deeper"), std::string::npos) << r.error().message;
  }
}

TEST(StorageReaderTest, AcceptsWhatYamlAndXmlAllowBeyondOpenCvsOwnOutput) {
  Result<StorageNode> y = ParseStorageText("# a comment\n%YAML 1.0\n",
                                           "f");  // a directive after the first line is refused...
  EXPECT_FALSE(y.ok());
  y = ParseStorageText(
      "%YAML 1.0\n---\n# comment\n'quoted key': \"a \\\"b\\\"\"  # trailing\n"
      "plain: it's text\nempty:\nseq:\n- 1\n- [2, 3]\n- k: v\n  k2: v2\n"
      "flow: {x: 1, 'y': [a, b]}\ncrlf: 7\r\n...\n",
      "f");
  ASSERT_TRUE(y.ok()) << y.error().ToString();
  ASSERT_TRUE(y->IsMap());
  EXPECT_EQ(y->Find("quoted key")->text, "a \"b\"");
  EXPECT_TRUE(y->Find("quoted key")->quoted);
  EXPECT_EQ(y->Find("plain")->text, "it's text");
  EXPECT_EQ(y->Find("empty")->kind, StorageNode::Kind::kNone);
  const StorageNode* seq = y->Find("seq");
  ASSERT_TRUE(seq != nullptr && seq->IsSeq());
  ASSERT_EQ(seq->items.size(), 3u);
  EXPECT_EQ(seq->items[1].items.size(), 2u);
  ASSERT_TRUE(seq->items[2].IsMap());
  EXPECT_EQ(seq->items[2].Find("k2")->text, "v2");
  EXPECT_EQ(y->Find("flow")->Find("y")->items[1].text, "b");
  long long crlf = 0;
  EXPECT_TRUE(y->Find("crlf")->AsInt(&crlf));
  EXPECT_EQ(crlf, 7);
  EXPECT_EQ(y->Find("seq")->items[0].line, 8);

  Result<StorageNode> x = ParseStorageText(
      "\xEF\xBB\xBF<?xml version=\"1.0\"?>\n<!-- c -->\n<opencv_storage>\n"
      "<s>\"x &amp; y\"</s><e/><q><_>1</_><_>2</_></q><c><![CDATA[5]]></c>\n"
      "<m type_id='opencv-matrix'><rows>1</rows><cols>1</cols><dt>d</dt><data>2.5</data></m>"
      "</opencv_storage>\n",
      "f");
  ASSERT_TRUE(x.ok()) << x.error().ToString();
  EXPECT_EQ(x->Find("s")->text, "x & y");
  EXPECT_EQ(x->Find("e")->kind, StorageNode::Kind::kNone);
  EXPECT_EQ(x->Find("q")->items.size(), 2u);
  long long five = 0;
  EXPECT_TRUE(x->Find("c")->AsInt(&five));
  EXPECT_EQ(five, 5);
  Result<Eigen::MatrixXd> one = StorageMatrix(*x->Find("m"), "f", "m", 4);
  ASSERT_TRUE(one.ok()) << one.error().ToString();
  EXPECT_EQ((*one)(0, 0), 2.5);

  // Quoted numbers are strings; numbers keep their exact value.
  Result<StorageNode> n = ParseStorageText("a: \"5\"\nb: 5\nc: -.Inf\nd: 1e999\ne: 0x10\n", "f");
  ASSERT_TRUE(n.ok());
  double v = 0;
  EXPECT_FALSE(n->Find("a")->AsNumber(&v));
  EXPECT_TRUE(n->Find("a")->IsString());
  EXPECT_TRUE(n->Find("b")->AsNumber(&v));
  EXPECT_TRUE(n->Find("c")->AsNumber(&v));
  EXPECT_EQ(v, -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(n->Find("d")->AsNumber(&v));
  EXPECT_TRUE(std::isinf(v));
  EXPECT_FALSE(n->Find("e")->AsNumber(&v));
}

TEST(StorageReaderTest, MatrixErrorsNameTheEntry) {
  const char* bad[] = {
      "M: !!opencv-matrix\n  rows: 2\n  cols: 2\n  dt: d\n  data: [1, 2, 3]\n",
      "M: !!opencv-matrix\n  rows: 100\n  cols: 100\n  dt: d\n  data: [1]\n",
      "M: !!opencv-matrix\n  rows: 1\n  cols: 2\n  dt: 3d\n  data: [1, 2]\n",
      "M: !!opencv-matrix\n  rows: 1\n  cols: 2\n  dt: d\n  data: [1, x]\n",
      "M: !!opencv-matrix\n  rows: 1\n  cols: 2\n  dt: d\n",
      "M: [1, [2]]\n",
      "M: 3\n",
  };
  for (const char* text : bad) {
    Result<StorageNode> file = ParseStorageText(text, "f");
    ASSERT_TRUE(file.ok()) << file.error().ToString();
    Result<Eigen::MatrixXd> m = StorageMatrix(*file->Find("M"), "f", "M", 64);
    ASSERT_FALSE(m.ok()) << text;
    EXPECT_EQ(m.error().code, ErrorCode::kInvalidArgument);
    EXPECT_NE(m.error().message.find("f: entry M "), std::string::npos) << m.error().message;
  }
}

}  // namespace
}  // namespace hpose
