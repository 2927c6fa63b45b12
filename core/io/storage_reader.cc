#include "core/io/storage_reader.h"

#include <algorithm>
#include <string_view>
#include <utility>
#include <vector>

#include "core/io/input_file.h"

namespace hpose {
namespace {

// Thrown inside this file only; ParseStorageText turns it into an Error.
struct ParseFailure {
  std::size_t pos;
  std::string what;
};

// Offsets of line starts, to name lines in messages and nodes.
class LineIndex {
 public:
  explicit LineIndex(std::string_view s) {
    starts_.push_back(0);
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (s[i] == '\n') starts_.push_back(i + 1);
    }
  }
  int LineOf(std::size_t pos) const {
    return static_cast<int>(std::upper_bound(starts_.begin(), starts_.end(), pos) -
                            starts_.begin());
  }
  std::size_t StartOf(std::size_t pos) const {
    return *(std::upper_bound(starts_.begin(), starts_.end(), pos) - 1);
  }

 private:
  std::vector<std::size_t> starts_;
};

void CheckNoDuplicateKeys(const StorageNode& map, std::size_t pos) {
  std::vector<std::string_view> keys;
  keys.reserve(map.members.size());
  for (const auto& member : map.members) keys.emplace_back(member.first);
  std::sort(keys.begin(), keys.end());
  const auto dup = std::adjacent_find(keys.begin(), keys.end());
  if (dup != keys.end()) throw ParseFailure{pos, "the key \"" + std::string(*dup) + "\" twice"};
}

bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r'; }

// YAML (block and flow) and JSON, which is YAML's flow syntax.
class YamlParser {
 public:
  YamlParser(std::string_view s, const LineIndex& lines) : s_(s), lines_(lines) {}

  StorageNode ParseDocument() {
    if (s_.substr(0, 5) == "%YAML") SkipRestOfLine();
    if (!SkipToContent()) return StorageNode{};
    StorageNode root = ParseBlockNode(-1, 0);
    if (SkipToContent()) throw ParseFailure{pos_, "content after the end of the document"};
    // After "---" or "...", only blank lines, comments and more markers may follow.
    while (ended_by_marker_) {
      ended_by_marker_ = false;
      SkipRestOfLine();
      if (SkipToContent()) throw ParseFailure{pos_, "more than one YAML document"};
    }
    return root;
  }

 private:
  bool AtEnd() const { return pos_ >= s_.size(); }
  char Peek(std::size_t ahead = 0) const {
    return pos_ + ahead < s_.size() ? s_[pos_ + ahead] : '\0';
  }
  int Column() const { return static_cast<int>(pos_ - lines_.StartOf(pos_)); }
  bool EndsToken(char c) const { return c == '\0' || c == ' ' || c == '\n' || IsSpace(c); }

  void SkipRestOfLine() {
    while (!AtEnd() && s_[pos_] != '\n') ++pos_;
  }

  // Moves to the first character of the next line with content, skipping blank and comment
  // lines; false at the end of the text or of the document ("---" or "..." at column 0).
  // Called only at the end of a line or on content already.
  bool SkipToContent() {
    if (ended_by_marker_) return false;
    while (!AtEnd()) {
      const char c = s_[pos_];
      if (c == '\n') {
        tab_in_indent_ = false;
        ++pos_;
        continue;
      }
      if (c == '\t') tab_in_indent_ = true;
      if (IsSpace(c)) {
        ++pos_;
        continue;
      }
      if (c == '#') {
        SkipRestOfLine();
        continue;
      }
      if (Column() == 0) {
        const std::string_view rest = s_.substr(pos_);
        if ((rest.substr(0, 3) == "---" || rest.substr(0, 3) == "...") &&
            (rest.size() == 3 || EndsToken(rest[3]))) {
          if (!seen_content_ && rest[0] == '-') {
            SkipRestOfLine();  // the document's start marker.
            continue;
          }
          ended_by_marker_ = true;
          return false;
        }
        if (c == '%') throw ParseFailure{pos_, "a \"%\" directive after the first line"};
      }
      if (tab_in_indent_) {
        throw ParseFailure{pos_, "a tab in the indentation (YAML indents with spaces)"};
      }
      seen_content_ = true;
      return true;
    }
    return false;
  }

  // After a value: only spaces and a comment may remain on the line.
  void ExpectLineEnd() {
    while (!AtEnd() && IsSpace(s_[pos_])) ++pos_;
    if (!AtEnd() && s_[pos_] == '#') SkipRestOfLine();
    if (!AtEnd() && s_[pos_] != '\n') {
      throw ParseFailure{pos_, std::string("unexpected \"") + s_[pos_] + "\" after a value"};
    }
  }

  void CheckDepth(int depth) const {
    if (depth > kMaxStorageDepth) {
      throw ParseFailure{pos_,
                         "nested deeper than " + std::to_string(kMaxStorageDepth) + " levels"};
    }
  }

  // Whether the line at pos_ holds "key:" (a map entry); the key ends where the colon is.
  bool AtMapKey() const {
    std::size_t i = pos_;
    if (i < s_.size() && (s_[i] == '"' || s_[i] == '\'')) {
      const char quote = s_[i++];
      while (i < s_.size() && s_[i] != quote && s_[i] != '\n') i += s_[i] == '\\' ? 2 : 1;
      if (i >= s_.size() || s_[i] != quote) return false;
      ++i;
      while (i < s_.size() && IsSpace(s_[i])) ++i;
      return i < s_.size() && s_[i] == ':';
    }
    if (i < s_.size() && (s_[i] == '[' || s_[i] == '{' || s_[i] == '#')) return false;
    for (; i < s_.size() && s_[i] != '\n'; ++i) {
      if (s_[i] == '#' && i > pos_ && IsSpace(s_[i - 1])) return false;
      if (s_[i] == ':' && (i + 1 == s_.size() || EndsToken(s_[i + 1]))) return true;
    }
    return false;
  }

  // A node whose first character is at pos_, in a block deeper than `parent_indent`.
  StorageNode ParseBlockNode(int parent_indent, int depth) {
    CheckDepth(depth);
    const int column = Column();
    if (column <= parent_indent) throw ParseFailure{pos_, "a value indented too little"};
    if (Peek() == '-' && EndsToken(Peek(1))) return ParseBlockSeq(column, depth);
    if (AtMapKey()) return ParseBlockMap(column, depth);
    StorageNode node = ParseInlineValue(depth);
    ExpectLineEnd();
    return node;
  }

  StorageNode ParseBlockMap(int indent, int depth) {
    StorageNode map;
    map.kind = StorageNode::Kind::kMap;
    map.line = lines_.LineOf(pos_);
    const std::size_t start = pos_;
    while (true) {
      if (!AtMapKey()) {
        throw ParseFailure{
            pos_, Peek() == '-' ? "a sequence item among map entries" : "expected \"key: value\""};
      }
      std::string key = ParseKey();
      map.members.emplace_back(std::move(key), ParseValueAfterIndicator(indent, true, depth));
      if (!SkipToContent() || Column() < indent) break;
      if (Column() > indent) throw ParseFailure{pos_, "unexpected indentation"};
    }
    CheckNoDuplicateKeys(map, start);
    return map;
  }

  StorageNode ParseBlockSeq(int indent, int depth) {
    StorageNode seq;
    seq.kind = StorageNode::Kind::kSeq;
    seq.line = lines_.LineOf(pos_);
    while (true) {
      if (!(Peek() == '-' && EndsToken(Peek(1)))) {
        throw ParseFailure{pos_, "expected a sequence item (\"- value\")"};
      }
      ++pos_;
      seq.items.push_back(ParseValueAfterIndicator(indent, false, depth));
      // A line at the same column that is no item ends a sequence nested in a map without
      // indentation ("key:\n- a\nnext: b"); the caller judges it otherwise.
      if (!SkipToContent() || Column() < indent || !(Peek() == '-' && EndsToken(Peek(1)))) {
        if (!AtEnd() && Column() > indent) throw ParseFailure{pos_, "unexpected indentation"};
        break;
      }
    }
    return seq;
  }

  std::string ParseKey() {
    std::string key;
    if (Peek() == '"' || Peek() == '\'') {
      key = ParseQuoted();
      while (IsSpace(Peek())) ++pos_;
    } else {
      const std::size_t begin = pos_;
      while (!AtEnd() && !(Peek() == ':' && EndsToken(Peek(1)))) ++pos_;
      std::size_t end = pos_;
      while (end > begin && IsSpace(s_[end - 1])) --end;
      key = std::string(s_.substr(begin, end - begin));
    }
    ++pos_;  // the colon (AtMapKey found it).
    return key;
  }

  // A tag such as "!!opencv-matrix" at pos_, without its "!"s; empty when there is none.
  std::string ParseTag() {
    if (Peek() != '!') return "";
    const std::size_t begin = pos_;
    while (!EndsToken(Peek())) ++pos_;
    std::string tag(s_.substr(begin, pos_ - begin));
    tag.erase(0, tag.find_first_not_of('!'));
    return tag;
  }

  // The value after "key:" or "- ": on the same line, or a block on the following lines.
  StorageNode ParseValueAfterIndicator(int indent, bool in_map, int depth) {
    while (IsSpace(Peek())) ++pos_;
    const std::string tag = ParseTag();
    while (IsSpace(Peek())) ++pos_;
    StorageNode node;
    if (AtEnd() || Peek() == '\n' || Peek() == '#') {
      const int line = lines_.LineOf(pos_);
      SkipRestOfLine();
      if (SkipToContent() && (Column() > indent || (in_map && Column() == indent && Peek() == '-' &&
                                                    EndsToken(Peek(1))))) {
        node = Column() > indent ? ParseBlockNode(indent, depth + 1)
                                 : ParseBlockSeq(indent, depth + 1);
      } else {
        node.line = line;  // nothing: an empty value.
      }
    } else if (!in_map && AtMapKey()) {
      node = ParseBlockMap(Column(), depth + 1);  // "- key: value" starts a map.
    } else if (!in_map && Peek() == '-' && EndsToken(Peek(1))) {
      node = ParseBlockSeq(Column(), depth + 1);
    } else {
      if (in_map && AtMapKey()) {
        throw ParseFailure{pos_, "a map entry on the same line as its key"};
      }
      node = ParseInlineValue(depth + 1);
      ExpectLineEnd();
    }
    node.type_id = tag;
    return node;
  }

  // A flow collection, a quoted scalar or a plain scalar up to the end of the line.
  StorageNode ParseInlineValue(int depth) {
    const char c = Peek();
    if (c == '[' || c == '{') return ParseFlow(depth);
    if (c == '|' || c == '>') throw ParseFailure{pos_, "block scalars (| or >) are not read"};
    if (c == '&' || c == '*') throw ParseFailure{pos_, "anchors and aliases are not read"};
    StorageNode node;
    node.kind = StorageNode::Kind::kScalar;
    node.line = lines_.LineOf(pos_);
    if (c == '"' || c == '\'') {
      node.text = ParseQuoted();
      node.quoted = true;
      return node;
    }
    const std::size_t begin = pos_;
    while (!AtEnd() && s_[pos_] != '\n' &&
           !(s_[pos_] == '#' && pos_ > begin && IsSpace(s_[pos_ - 1]))) {
      ++pos_;
    }
    std::size_t end = pos_;
    while (end > begin && IsSpace(s_[end - 1])) --end;
    node.text = std::string(s_.substr(begin, end - begin));
    return node;
  }

  std::string ParseQuoted() {
    const std::size_t open = pos_;
    const char quote = s_[pos_++];
    std::string out;
    while (true) {
      if (AtEnd()) throw ParseFailure{open, "a quoted string that never ends"};
      const char c = s_[pos_++];
      if (c == quote) {
        if (quote == '\'' && Peek() == '\'') {  // '' is a quote inside '...'.
          out += '\'';
          ++pos_;
          continue;
        }
        return out;
      }
      if (c == '\\' && quote == '"') {
        if (AtEnd()) throw ParseFailure{open, "a quoted string that never ends"};
        const char e = s_[pos_++];
        out += e == 'n' ? '\n' : e == 't' ? '\t' : e == 'r' ? '\r' : e == '0' ? '\0' : e;
        continue;
      }
      out += c;
    }
  }

  void SkipFlowSpace() {
    while (!AtEnd()) {
      const char c = s_[pos_];
      if (c == '\n' || IsSpace(c)) {
        ++pos_;
      } else if (c == '#') {
        SkipRestOfLine();
      } else {
        break;
      }
    }
  }

  // [ a, b ] or { k: v, "k": v }, across lines; JSON is this syntax.
  StorageNode ParseFlow(int depth) {
    CheckDepth(depth);
    const std::size_t open = pos_;
    const bool is_seq = s_[pos_++] == '[';
    const char close = is_seq ? ']' : '}';
    StorageNode node;
    node.kind = is_seq ? StorageNode::Kind::kSeq : StorageNode::Kind::kMap;
    node.line = lines_.LineOf(open);
    while (true) {
      SkipFlowSpace();
      if (AtEnd()) {
        throw ParseFailure{open,
                           std::string("a ") + (is_seq ? "[" : "{") + " never closed by " + close};
      }
      if (Peek() == close) {
        ++pos_;
        break;
      }
      if (is_seq) {
        node.items.push_back(ParseFlowValue(depth));
      } else {
        std::string key = ParseFlowKey();
        node.members.emplace_back(std::move(key), ParseFlowValue(depth));
      }
      SkipFlowSpace();
      if (Peek() == ',') {
        ++pos_;
      } else if (Peek() != close && !AtEnd()) {
        throw ParseFailure{pos_, std::string("expected \",\" or \"") + close + "\""};
      }
    }
    if (!is_seq) {
      CheckNoDuplicateKeys(node, open);
      const StorageNode* type = node.Find("type_id");
      if (type != nullptr && type->IsScalar()) node.type_id = type->text;
    }
    return node;
  }

  std::string ParseFlowKey() {
    std::string key;
    if (Peek() == '"' || Peek() == '\'') {
      key = ParseQuoted();
    } else {
      const std::size_t begin = pos_;
      while (!AtEnd() && s_[pos_] != ':' && s_[pos_] != ',' && s_[pos_] != '}' &&
             s_[pos_] != '\n') {
        ++pos_;
      }
      std::size_t end = pos_;
      while (end > begin && IsSpace(s_[end - 1])) --end;
      key = std::string(s_.substr(begin, end - begin));
    }
    SkipFlowSpace();
    if (Peek() != ':') throw ParseFailure{pos_, "expected \":\" after a key"};
    ++pos_;
    return key;
  }

  StorageNode ParseFlowValue(int depth) {
    SkipFlowSpace();
    const std::string tag = ParseTag();
    SkipFlowSpace();
    StorageNode node;
    const char c = Peek();
    if (c == '[' || c == '{') {
      node = ParseFlow(depth + 1);
    } else if (c == '"' || c == '\'') {
      node.kind = StorageNode::Kind::kScalar;
      node.line = lines_.LineOf(pos_);
      node.text = ParseQuoted();
      node.quoted = true;
    } else {
      node.kind = StorageNode::Kind::kScalar;
      node.line = lines_.LineOf(pos_);
      const std::size_t begin = pos_;
      while (!AtEnd() && s_[pos_] != ',' && s_[pos_] != ']' && s_[pos_] != '}' &&
             s_[pos_] != '\n' && !(s_[pos_] == '#' && pos_ > begin && IsSpace(s_[pos_ - 1]))) {
        ++pos_;
      }
      std::size_t end = pos_;
      while (end > begin && IsSpace(s_[end - 1])) --end;
      if (end == begin) throw ParseFailure{begin, "expected a value"};
      node.text = std::string(s_.substr(begin, end - begin));
    }
    if (!tag.empty()) node.type_id = tag;
    return node;
  }

  std::string_view s_;
  const LineIndex& lines_;
  std::size_t pos_ = 0;
  bool seen_content_ = false;
  bool ended_by_marker_ = false;
  bool tab_in_indent_ = false;
};

// OpenCV's XML layout: <opencv_storage> with one element per entry.
class XmlParser {
 public:
  XmlParser(std::string_view s, const LineIndex& lines) : s_(s), lines_(lines) {}

  StorageNode ParseDocument() {
    SkipMisc();
    if (Peek() != '<') throw ParseFailure{pos_, "expected the <opencv_storage> element"};
    ++pos_;
    std::string name = ParseName();
    if (name != "opencv_storage") {
      throw ParseFailure{pos_, "the root element is <" + name + ">, not <opencv_storage>"};
    }
    StorageNode root = ParseElement(name, 0);
    SkipMisc();
    if (!AtEnd()) throw ParseFailure{pos_, "content after </opencv_storage>"};
    return root;
  }

 private:
  bool AtEnd() const { return pos_ >= s_.size(); }
  char Peek() const { return pos_ < s_.size() ? s_[pos_] : '\0'; }
  bool StartsWith(std::string_view what) const { return s_.substr(pos_, what.size()) == what; }

  void SkipPast(std::string_view end, const char* what) {
    const std::size_t found = s_.find(end, pos_);
    if (found == std::string_view::npos) {
      throw ParseFailure{pos_, std::string(what) + " that never ends"};
    }
    pos_ = found + end.size();
  }

  void SkipSpace() {
    while (!AtEnd() && (IsSpace(s_[pos_]) || s_[pos_] == '\n')) ++pos_;
  }

  // Space, <?...?> declarations and comments outside the root element.
  void SkipMisc() {
    if (StartsWith("\xEF\xBB\xBF")) pos_ += 3;  // a UTF-8 byte order mark.
    while (true) {
      SkipSpace();
      if (StartsWith("<?")) {
        SkipPast("?>", "a <? declaration");
      } else if (StartsWith("<!--")) {
        SkipPast("-->", "a comment");
      } else if (StartsWith("<!")) {
        throw ParseFailure{pos_, "DOCTYPE and other <! declarations are not read"};
      } else {
        return;
      }
    }
  }

  static bool IsNameChar(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-' || c == '.' || c == ':';
  }

  std::string ParseName() {
    const std::size_t begin = pos_;
    while (!AtEnd() && IsNameChar(s_[pos_])) ++pos_;
    if (pos_ == begin) throw ParseFailure{pos_, "expected an element or attribute name"};
    return std::string(s_.substr(begin, pos_ - begin));
  }

  void AppendDecoded(std::string_view raw, std::size_t at, std::string* out) const {
    for (std::size_t i = 0; i < raw.size(); ++i) {
      if (raw[i] != '&') {
        *out += raw[i];
        continue;
      }
      const std::size_t semi = raw.find(';', i);
      if (semi == std::string_view::npos || semi - i > 10) {
        throw ParseFailure{at + i, "a \"&\" that starts no entity"};
      }
      const std::string_view entity = raw.substr(i + 1, semi - i - 1);
      if (entity == "lt") {
        *out += '<';
      } else if (entity == "gt") {
        *out += '>';
      } else if (entity == "amp") {
        *out += '&';
      } else if (entity == "quot") {
        *out += '"';
      } else if (entity == "apos") {
        *out += '\'';
      } else if (entity.size() >= 2 && entity[0] == '#') {
        const bool hex = entity[1] == 'x';
        unsigned long code = 0;
        for (char c : entity.substr(hex ? 2 : 1)) {
          const int digit = c >= '0' && c <= '9'          ? c - '0'
                            : hex && c >= 'a' && c <= 'f' ? c - 'a' + 10
                            : hex && c >= 'A' && c <= 'F' ? c - 'A' + 10
                                                          : -1;
          if (digit < 0) throw ParseFailure{at + i, "a malformed character reference"};
          code = code * (hex ? 16 : 10) + static_cast<unsigned long>(digit);
        }
        *out += code < 128 ? static_cast<char>(code) : '?';
      } else {
        throw ParseFailure{at + i, "the unknown entity &" + std::string(entity) + ";"};
      }
      i = semi;
    }
  }

  // The rest of an element after "<name": attributes, then content up to </name>.
  StorageNode ParseElement(const std::string& name, int depth) {
    if (depth > kMaxStorageDepth) {
      throw ParseFailure{pos_,
                         "nested deeper than " + std::to_string(kMaxStorageDepth) + " levels"};
    }
    StorageNode node;
    const std::size_t open = pos_;
    node.line = lines_.LineOf(pos_);
    while (true) {
      SkipSpace();
      if (StartsWith("/>")) {
        pos_ += 2;
        return node;
      }
      if (Peek() == '>') {
        ++pos_;
        break;
      }
      const std::string attribute = ParseName();
      SkipSpace();
      if (Peek() != '=') throw ParseFailure{pos_, "expected \"=\" after attribute " + attribute};
      ++pos_;
      SkipSpace();
      const char quote = Peek();
      if (quote != '"' && quote != '\'') throw ParseFailure{pos_, "an unquoted attribute value"};
      const std::size_t close = s_.find(quote, pos_ + 1);
      if (close == std::string_view::npos) {
        throw ParseFailure{pos_, "an attribute value that never ends"};
      }
      std::string value;
      AppendDecoded(s_.substr(pos_ + 1, close - pos_ - 1), pos_ + 1, &value);
      pos_ = close + 1;
      if (attribute == "type_id") node.type_id = value;
    }
    std::string text;
    std::vector<std::pair<std::string, StorageNode>> children;
    while (true) {
      if (AtEnd()) throw ParseFailure{open, "<" + name + "> never closed"};
      if (Peek() != '<') {
        const std::size_t next = std::min(s_.find('<', pos_), s_.size());
        AppendDecoded(s_.substr(pos_, next - pos_), pos_, &text);
        pos_ = next;
      } else if (StartsWith("<!--")) {
        SkipPast("-->", "a comment");
      } else if (StartsWith("<![CDATA[")) {
        const std::size_t begin = pos_ + 9;
        SkipPast("]]>", "a CDATA section");
        text.append(s_.substr(begin, pos_ - 3 - begin));
      } else if (StartsWith("<?")) {
        SkipPast("?>", "a <? instruction");
      } else if (StartsWith("</")) {
        pos_ += 2;
        const std::string closing = ParseName();
        if (closing != name) {
          throw ParseFailure{pos_, "</" + closing + "> closes <" + name + ">"};
        }
        SkipSpace();
        if (Peek() != '>') throw ParseFailure{pos_, "expected \">\" after </" + name};
        ++pos_;
        break;
      } else {
        ++pos_;
        std::string child = ParseName();
        StorageNode value = ParseElement(child, depth + 1);
        children.emplace_back(std::move(child), std::move(value));
      }
    }
    if (!children.empty()) {
      if (text.find_first_not_of(" \t\r\n") != std::string::npos) {
        throw ParseFailure{pos_, "<" + name + "> mixes text with elements"};
      }
      const bool all_items = std::all_of(children.begin(), children.end(),
                                         [](const auto& c) { return c.first == "_"; });
      if (all_items) {
        node.kind = StorageNode::Kind::kSeq;
        for (auto& child : children) node.items.push_back(std::move(child.second));
      } else {
        node.kind = StorageNode::Kind::kMap;
        node.members = std::move(children);
        for (const auto& member : node.members) {
          if (member.first == "_") {
            throw ParseFailure{pos_, "<" + name + "> mixes <_> items with named entries"};
          }
        }
        CheckNoDuplicateKeys(node, pos_);
      }
      return node;
    }
    std::vector<StorageNode> tokens = Tokens(text, node.line);
    if (tokens.size() == 1) {
      StorageNode scalar = std::move(tokens[0]);
      scalar.type_id = node.type_id;
      return scalar;
    }
    if (!tokens.empty()) {
      node.kind = StorageNode::Kind::kSeq;
      node.items = std::move(tokens);
    }
    return node;
  }

  // Whitespace-separated values; "double quoted" ones may hold spaces.
  std::vector<StorageNode> Tokens(const std::string& text, int line) const {
    std::vector<StorageNode> out;
    std::size_t i = 0;
    while (true) {
      while (i < text.size() && (IsSpace(text[i]) || text[i] == '\n')) ++i;
      if (i >= text.size()) return out;
      StorageNode token;
      token.kind = StorageNode::Kind::kScalar;
      token.line = line;
      if (text[i] == '"') {
        const std::size_t close = text.find('"', i + 1);
        if (close == std::string::npos) throw ParseFailure{pos_, "a quoted value that never ends"};
        token.text = text.substr(i + 1, close - i - 1);
        token.quoted = true;
        i = close + 1;
      } else {
        const std::size_t begin = i;
        while (i < text.size() && !IsSpace(text[i]) && text[i] != '\n') ++i;
        token.text = text.substr(begin, i - begin);
      }
      out.push_back(std::move(token));
    }
  }

  std::string_view s_;
  const LineIndex& lines_;
  std::size_t pos_ = 0;
};

}  // namespace

Result<StorageNode> ParseStorageText(std::string_view text, const std::string& origin) {
  const LineIndex lines(text);
  std::size_t first = 0;
  if (text.substr(0, 3) == "\xEF\xBB\xBF") first = 3;
  while (first < text.size() && (IsSpace(text[first]) || text[first] == '\n')) ++first;
  try {
    if (first < text.size() && text[first] == '<') return XmlParser(text, lines).ParseDocument();
    return YamlParser(text, lines).ParseDocument();
  } catch (const ParseFailure& failure) {
    return MakeError(ErrorCode::kDataLoss,
                     origin + ": line " + std::to_string(lines.LineOf(failure.pos)) + ": " +
                         failure.what + "; not an OpenCV FileStorage file (YAML, XML or JSON)");
  }
}

Result<Eigen::MatrixXd> StorageMatrix(const StorageNode& node, const std::string& where,
                                      const std::string& name, int max_values) {
  const std::string limit = "at most " + std::to_string(max_values) + " values";
  auto fail = [&](const std::string& what) {
    return MakeError(ErrorCode::kInvalidArgument, where + ": entry " + name + " " + what);
  };
  const std::vector<StorageNode>* values = nullptr;
  long long rows = 1, cols = 0;
  if (node.IsSeq()) {
    values = &node.items;
    cols = static_cast<long long>(node.items.size());
  } else if (node.IsMap()) {
    const StorageNode* r = node.Find("rows");
    const StorageNode* c = node.Find("cols");
    const StorageNode* dt = node.Find("dt");
    const StorageNode* data = node.Find("data");
    if (r == nullptr || c == nullptr || dt == nullptr || data == nullptr) {
      return fail("is not a matrix (rows, cols, dt, data)");
    }
    if (!r->AsInt(&rows) || !c->AsInt(&cols) || rows < 1 || cols < 1 || rows > max_values ||
        cols > max_values || rows * cols > max_values) {
      return fail("is not a matrix of " + limit + " (rows, cols, dt, data)");
    }
    static const std::string kTypes = "ucwsifdh";
    if (!dt->IsScalar() || dt->text.size() != 1 || kTypes.find(dt->text[0]) == std::string::npos) {
      return fail("has dt \"" + dt->text + "\"; one channel of u, c, w, s, i, f, d or h is read");
    }
    // XML writes a single value without a sequence around it.
    if (data->IsScalar() && rows * cols == 1) {
      double v = 0;
      if (!data->AsNumber(&v)) return fail("holds \"" + data->text + "\", not a number");
      return Eigen::MatrixXd(Eigen::MatrixXd::Constant(1, 1, v));
    }
    if (!data->IsSeq()) return fail("has no data sequence");
    values = &data->items;
  } else {
    return fail(node.IsScalar() ? "is a single value, not a matrix" : "is empty");
  }
  if (values->empty()) return fail("is empty");
  if (static_cast<long long>(values->size()) != rows * cols) {
    return fail("holds " + std::to_string(values->size()) +
                " values, not rows x cols = " + std::to_string(rows * cols));
  }
  if (cols > max_values) return fail("is not a matrix of " + limit);
  Eigen::MatrixXd m(rows, cols);
  for (long long i = 0; i < rows * cols; ++i) {
    const StorageNode& v = (*values)[static_cast<std::size_t>(i)];
    if (!v.AsNumber(&m(i / cols, i % cols))) {
      return fail("holds " + (v.IsScalar() ? "\"" + v.text + "\"" : std::string("a collection")) +
                  ", not a number");
    }
  }
  return m;
}

Result<StorageNode> ReadStorageFile(const std::string& path, std::uint64_t max_bytes) {
  Result<std::uint64_t> size = CheckInputFile(path, max_bytes);
  if (!size.ok()) return size.error();
  Result<std::string> text = ReadFileHead(path, static_cast<std::size_t>(*size));
  if (!text.ok()) return text.error();
  return ParseStorageText(*text, path);
}

}  // namespace hpose
