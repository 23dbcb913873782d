#include "penumbra/output/pcd_writer.h"

#include <cstring>
#include <fstream>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"

namespace penumbra {
namespace {
constexpr size_t kRecord = 4 * 4 + 2 + 4;  // x y z intensity ring time
}

std::string EncodePcd(const std::vector<LidarPoint>& points) {
  std::ostringstream h;
  h << "# .PCD v0.7 - Point Cloud Data file format\n"
    << "VERSION 0.7\nFIELDS x y z intensity ring time\nSIZE 4 4 4 4 2 4\n"
    << "TYPE F F F F U F\nCOUNT 1 1 1 1 1 1\nWIDTH " << points.size() << "\nHEIGHT 1\n"
    << "VIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points.size() << "\nDATA binary\n";
  std::string data(points.size() * kRecord, '\0');
  char* p = data.data();
  for (const LidarPoint& q : points) {
    std::memcpy(p, &q.x, 4);
    std::memcpy(p + 4, &q.y, 4);
    std::memcpy(p + 8, &q.z, 4);
    std::memcpy(p + 12, &q.intensity, 4);
    std::memcpy(p + 16, &q.ring, 2);
    std::memcpy(p + 18, &q.time, 4);
    p += kRecord;
  }
  return h.str() + data;
}

void WritePcd(const std::string& path, const std::vector<LidarPoint>& points) {
  WriteFileAtomic(path, EncodePcd(points));
}

std::vector<LidarPoint> ReadPcd(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw Error("cannot open '" + path + "'");
  std::string line;
  size_t n = 0;
  bool binary = false;
  while (std::getline(f, line)) {
    if (line.rfind("POINTS ", 0) == 0) n = std::stoul(line.substr(7));
    if (line.rfind("FIELDS ", 0) == 0 && line != "FIELDS x y z intensity ring time")
      throw Error("'" + path + "': unexpected fields '" + line + "'");
    if (line.rfind("DATA ", 0) == 0) {
      binary = line == "DATA binary";
      break;
    }
  }
  if (!binary) throw Error("'" + path + "': not a binary PCD file");
  std::string data(n * kRecord, '\0');
  f.read(data.data(), static_cast<std::streamsize>(data.size()));
  if (static_cast<size_t>(f.gcount()) != data.size()) throw Error("'" + path + "': truncated");
  std::vector<LidarPoint> out(n);
  const char* p = data.data();
  for (LidarPoint& q : out) {
    std::memcpy(&q.x, p, 4);
    std::memcpy(&q.y, p + 4, 4);
    std::memcpy(&q.z, p + 8, 4);
    std::memcpy(&q.intensity, p + 12, 4);
    std::memcpy(&q.ring, p + 16, 2);
    std::memcpy(&q.time, p + 18, 4);
    p += kRecord;
  }
  return out;
}

}  // namespace penumbra
