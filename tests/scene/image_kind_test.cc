// the image-kind table (scene/image_kind.h): order, names, folders, encodings, and the
// indexed set cameras use.
#include "penumbra/scene/image_kind.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

#include "penumbra/scene/scene_description.h"

namespace penumbra {
namespace {

TEST(ImageKind, TableListsEveryKindOnceInEnumOrder) {
  std::set<std::string_view> names, folders;
  for (int i = 0; i < kImageKindCount; ++i) {
    const ImageKindInfo& k = kImageKinds[i];
    EXPECT_EQ(static_cast<int>(k.kind), i);
    EXPECT_TRUE(names.insert(k.name).second) << k.name;
    EXPECT_TRUE(folders.insert(k.folder).second) << k.folder;
    EXPECT_EQ(ImageKindFromName(k.name), k.kind);
    EXPECT_TRUE(IsImageKindFolder(k.folder));
  }
  EXPECT_FALSE(ImageKindFromName("lidar"));
  EXPECT_FALSE(IsImageKindFolder("imu"));
}

TEST(ImageKind, NamesFoldersAndEncodingsOfARunAreTheDocumentedOnes) {
  // the world file's `outputs` names and the run folders (docs/cameras.md, camera_writer.h)
  const char* expected[] = {"rgb",
                            "depth",
                            "segmentation",
                            "range",
                            "normals",
                            "instance_segmentation",
                            "semantic_segmentation"};
  for (int i = 0; i < kImageKindCount; ++i) {
    EXPECT_EQ(kImageKinds[i].name, expected[i]);
    EXPECT_EQ(kImageKinds[i].folder, expected[i]);
  }
  EXPECT_EQ(Info(ImageKind::kRgb).pixel, PixelType::kU8);
  EXPECT_EQ(Info(ImageKind::kRgb).channels, 3);
  EXPECT_EQ(Info(ImageKind::kNormals).pixel, PixelType::kF32);
  EXPECT_EQ(Info(ImageKind::kNormals).channels, 3);
  EXPECT_EQ(Info(ImageKind::kDepth).encoding, ImageEncoding::kPngGray16Millimetres);
  EXPECT_EQ(Info(ImageKind::kSegmentation).encoding, ImageEncoding::kPngGray16IdPlusOne);
  EXPECT_EQ(Info(ImageKind::kSemanticSegmentation).encoding, ImageEncoding::kPngGray16Id);
  // uncompressed bytes per pixel: 8-bit x 3 for rgb and normals, 16-bit x 1 for the others
  int bytes = 0;
  for (const ImageKindInfo& k : kImageKinds) bytes += EncodedBytesPerPixel(k.encoding);
  EXPECT_EQ(bytes, 3 + 3 + 5 * 2);
}

TEST(ImageKindSet, IsIndexedByKindAndCameraOutputsStartWithRgbOnly) {
  CameraOutputs o;
  EXPECT_TRUE(o[ImageKind::kRgb]);
  EXPECT_EQ(o.count(), 1);
  o[ImageKind::kNormals] = true;
  EXPECT_TRUE(o[ImageKind::kNormals]);
  EXPECT_EQ(o.count(), 2);
  EXPECT_TRUE(CameraOutputs::None().empty());
  CameraOutputs n = CameraOutputs::None();
  bool* depth = n.Flag("depth");
  ASSERT_NE(depth, nullptr);
  *depth = true;
  EXPECT_TRUE(n[ImageKind::kDepth]);
  EXPECT_EQ(n.Flag("sonar"), nullptr);
  EXPECT_EQ(n, (CameraOutputs{ImageKind::kDepth}));
  EXPECT_NE(n, o);
}

}  // namespace
}  // namespace penumbra
