#pragma once
// Point Cloud Library PCD v0.7 files (binary), as PCL's "The PCD (Point Cloud Data) file
// format" documentation specifies: header lines VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH,
// HEIGHT, VIEWPOINT, POINTS, DATA binary, then the points as packed little-endian records.

#include <string>
#include <vector>

#include "penumbra/sensors/lidar_scanner.h"

namespace penumbra {

/// the bytes of a binary PCD v0.7 file of `points` (the format WritePcd writes).
std::string EncodePcd(const std::vector<LidarPoint>& points);

/// writes `points` as binary PCD v0.7 with fields x y z intensity (float32), ring (uint16),
/// time (float32, s since the scan start); WIDTH = number of points, HEIGHT = 1.
/// @throws Error if the file cannot be written.
void WritePcd(const std::string& path, const std::vector<LidarPoint>& points);

/// reads a file written by WritePcd (for tests and tools).
/// @throws Error if the file is not such a PCD file.
std::vector<LidarPoint> ReadPcd(const std::string& path);

}  // namespace penumbra
