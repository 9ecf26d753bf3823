#include "nn/presets.h"

#include <initializer_list>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "nn/conv2d.h"
#include "tests/nn/gradient_check.h"

namespace rl::nn {
namespace {

std::vector<float> Flat(const Sequential& net) {
  std::vector<float> flat;
  net.GetFlat(&flat);
  return flat;
}

// Expects the image shape after each listed layer (layer index, shape).
void ExpectLayerShapes(const Sequential& net,
                       std::initializer_list<std::pair<int, ImageShape>> shapes) {
  for (const auto& [layer, shape] : shapes) {
    EXPECT_EQ(net.layer(layer).output_shape(), shape) << "layer " << layer;
  }
}

// Runs `batch` random observations in [0, 1] through *net: a column of `actions` finite
// Q-values each.
void ExpectQValues(Sequential* net, int actions, int batch, std::mt19937* rng) {
  const Matrix x = RandomMatrix(net->InputSize(), batch, rng, 0.5f).array() + 0.5f;
  const Matrix& q = net->Forward(x);
  EXPECT_EQ(q.rows(), actions);
  EXPECT_EQ(q.cols(), batch);
  EXPECT_TRUE(q.allFinite());
}

TEST(PresetsTest, NatureCnnHasThePyTorchShapesAndParameterCount) {
  std::mt19937 rng(0);
  Sequential net = MakeNatureCnn(7, &rng);
  EXPECT_EQ(net.Architecture(),
            "conv2d(4,32,8,4,0,84,84),relu,conv2d(32,64,4,2,0,20,20),relu,"
            "conv2d(64,64,3,1,0,9,9),relu,flatten,linear(3136,512),relu,linear(512,7)");
  EXPECT_EQ(net.InputSize(), 4 * 84 * 84);
  EXPECT_EQ(net.OutputSize(), 7);
  // Spatial sizes 84 -> 20 -> 9 -> 7, so the flattened features are 64 * 7 * 7 = 3136.
  EXPECT_EQ(net.layer(4).output_shape(), (ImageShape{64, 7, 7}));
  const int64_t expected = (4 * 32 * 8 * 8 + 32)     // conv1: 8,224
                           + (32 * 64 * 4 * 4 + 64)  // conv2: 32,832
                           + (64 * 64 * 3 * 3 + 64)  // conv3: 36,928
                           + (3136 * 512 + 512)      // fc: 1,606,144
                           + (512 * 7 + 7);          // out: 3,591
  EXPECT_EQ(expected, 1687719);
  EXPECT_EQ(net.NumParams(), 1687719);
  EXPECT_EQ(net.NumBuffers(), 0);
  EXPECT_EQ(net.Params()[0].value->rows(), 4 * 8 * 8);
  EXPECT_EQ(net.Params()[0].value->cols(), 32);
  ExpectQValues(&net, 7, 3, &rng);
}

TEST(PresetsTest, GraspCnnHasThePyTorchShapesAndParameterCount) {
  std::mt19937 rng(1);
  Sequential net = MakeGraspCnn(7, &rng);
  EXPECT_EQ(net.Architecture(), GraspCnnArchitecture(7, 4));
  EXPECT_EQ(net.InputSize(), 4 * 40 * 40);
  // 40 -> 9 -> 3 -> 1.
  ExpectLayerShapes(net, {{0, {32, 9, 9}}, {3, {64, 3, 3}}, {6, {64, 1, 1}}});
  ExpectQValues(&net, 7, 5, &rng);
  const int64_t expected = (4 * 32 * 8 * 8 + 32)     // conv1: 8,224
                           + 2 * 32                  // bn1 weight and bias: 64
                           + (32 * 64 * 4 * 4 + 64)  // conv2: 32,832
                           + 2 * 64                  // bn2: 128
                           + (64 * 64 * 3 * 3 + 64)  // conv3: 36,928
                           + (64 * 512 + 512)        // fc: 33,280
                           + (512 * 7 + 7);          // out: 3,591
  EXPECT_EQ(expected, 115047);
  EXPECT_EQ(net.NumParams(), 115047);
  EXPECT_EQ(net.NumBuffers(), 2 * 32 + 2 * 64);
  EXPECT_EQ(MakeGraspCnn(3, &rng, /*in_channels=*/1).InputSize(), 40 * 40);
}

TEST(PresetsTest, Grasp48CnnKeepsASixBySixMap) {
  std::mt19937 rng(6);
  Sequential net = MakeGrasp48Cnn(7, &rng);
  EXPECT_EQ(net.Architecture(), Grasp48CnnArchitecture(7, 4));
  EXPECT_EQ(net.InputSize(), 4 * 48 * 48);
  const int64_t expected = (4 * 16 * 5 * 5 + 16)     // conv1: 1,616
                           + (16 * 32 * 3 * 3 + 32)  // conv2: 4,640
                           + (32 * 32 * 3 * 3 + 32)  // conv3: 9,248
                           + (1152 * 256 + 256)      // fc: 295,168
                           + (256 * 7 + 7);          // out: 1,799
  EXPECT_EQ(expected, 312471);
  EXPECT_EQ(net.NumParams(), 312471);
  EXPECT_EQ(net.NumBuffers(), 0);
  // 48 -> 24 -> 12 -> 6.
  ExpectLayerShapes(net, {{0, {16, 24, 24}}, {2, {32, 12, 12}}, {4, {32, 6, 6}}});
  EXPECT_EQ(MakeGrasp48Cnn(3, &rng, /*in_channels=*/1).InputSize(), 48 * 48);
  const Sequential dueling = MakeGrasp48Cnn(7, &rng, 4, /*dueling=*/true);
  EXPECT_NE(dueling.Architecture().find("flatten,dueling(1152,256,7)"), std::string::npos);
  ExpectQValues(&net, 7, 5, &rng);
  EXPECT_THROW(Grasp48CnnArchitecture(0), std::invalid_argument);
  EXPECT_THROW(MakeGrasp48Cnn(3, &rng, 0), std::invalid_argument);
}

TEST(PresetsTest, DuelingVariantsReplaceTheFullyConnectedHead) {
  std::mt19937 rng(2);
  const Sequential nature = MakeNatureCnn(6, &rng, /*dueling=*/true);
  EXPECT_EQ(nature.Architecture(), NatureCnnArchitecture(6, true));
  EXPECT_NE(nature.Architecture().find("flatten,dueling(3136,512,6)"), std::string::npos);
  EXPECT_EQ(nature.NumParams(),
            77984 + (3136 * 512 + 512) + (512 + 1) + (3136 * 512 + 512) + (512 * 6 + 6));
  const Sequential grasp = MakeGraspCnn(5, &rng, 2, /*dueling=*/true);
  EXPECT_NE(grasp.Architecture().find("flatten,dueling(64,512,5)"), std::string::npos);
  EXPECT_EQ(grasp.OutputSize(), 5);
}

TEST(PresetsTest, ArchitectureStringsRebuildTheSameNetworks) {
  for (const std::string& arch : {NatureCnnArchitecture(7), GraspCnnArchitecture(4, 3, true)}) {
    std::mt19937 rng_a(9);
    std::mt19937 rng_b(9);
    const Sequential built = BuildFromArchitecture(arch, &rng_a);
    EXPECT_EQ(built.Architecture(), arch);
    EXPECT_EQ(Flat(built), Flat(BuildFromArchitecture(built.Architecture(), &rng_b)));
  }
  std::mt19937 rng_a(5);
  std::mt19937 rng_b(5);
  EXPECT_EQ(Flat(MakeNatureCnn(7, &rng_a)),
            Flat(BuildFromArchitecture(NatureCnnArchitecture(7), &rng_b)));
}

TEST(PresetsTest, GetFlatSetFlatCarriesBatchNormStatisticsToAnotherNetwork) {
  std::mt19937 rng(3);
  Sequential learner = MakeGraspCnn(4, &rng);
  // A few training passes move the running statistics.
  for (int i = 0; i < 3; ++i) {
    learner.Forward(RandomMatrix(learner.InputSize(), 8, &rng, 0.5f).array() + 0.5f);
  }
  Sequential actor = BuildFromArchitecture(learner.Architecture(), &rng);
  const std::vector<float> flat = Flat(learner);
  ASSERT_EQ(flat.size(), static_cast<size_t>(learner.NumParams() + 192));
  actor.SetFlat(flat.data(), flat.size());
  EXPECT_EQ(Flat(actor), flat);
  const Matrix obs = RandomMatrix(learner.InputSize(), 1, &rng, 0.5f).array() + 0.5f;
  EXPECT_EQ(Matrix(actor.Predict(obs.data(), static_cast<int>(obs.size()))),
            Matrix(learner.Predict(obs.data(), static_cast<int>(obs.size()))));
}

TEST(PresetsTest, RejectNonPositiveSizes) {
  std::mt19937 rng(4);
  EXPECT_THROW(NatureCnnArchitecture(0), std::invalid_argument);
  EXPECT_THROW(MakeGraspCnn(3, &rng, 0), std::invalid_argument);
}

}  // namespace
}  // namespace rl::nn
