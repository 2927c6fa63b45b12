#ifndef HPOSE_SERVER_MESSAGE_JSON_H_
#define HPOSE_SERVER_MESSAGE_JSON_H_

#include <string>

namespace google::protobuf {
class Message;
}

namespace hpose::server {

// One line of JSON for an API message, the schema shared by `hpose estimate --json`,
// `hpose replay` (JSON Lines) and `hpose query --json` (docs/API.md lists it field by field).
// Unlike proto3's JSON mapping, every field is always present:
//   - numbers, booleans and strings appear even when zero, false or empty;
//   - 64-bit integers are JSON numbers, not strings;
//   - enums are their names ("ESTIMATOR_KIND_DEPTH_TEMPLATE");
//   - a message field that is not set, and the members of a oneof other than the one set, are
//     null (a set message is an object with all of its fields);
//   - google.protobuf.Timestamp is an RFC 3339 string in UTC;
//   - repeated fields are arrays (possibly empty); bytes are base64 strings;
//   - non-finite doubles (NaN, infinities) are null.
// Field names are the .proto names (snake_case).
std::string MessageToJsonLine(const google::protobuf::Message& message);

}  // namespace hpose::server

#endif  // HPOSE_SERVER_MESSAGE_JSON_H_
