#include "nn/sequential.h"

#include <array>
#include <memory>
#include <random>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "nn/activations.h"
#include "nn/linear.h"
#include "nn/losses.h"
#include "tests/nn/gradient_check.h"

namespace rl::nn {
namespace {

constexpr char kCartPoleArch[] = "linear(4,120),relu,linear(120,84),relu,linear(84,2)";

std::vector<float> Flat(const Sequential& net) {
  std::vector<float> flat;
  net.GetFlat(&flat);
  return flat;
}

// Expects BuildFromArchitecture to throw std::invalid_argument for each architecture string,
// with a message that contains the case's text.
void ExpectRefused(std::span<const std::pair<std::string, std::string>> cases) {
  std::mt19937 rng(0);
  for (const auto& [arch, message] : cases) {
    try {
      BuildFromArchitecture(arch, &rng);
      ADD_FAILURE() << "no exception for '" << arch << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos)
          << "'" << arch << "' gave: " << e.what();
    }
  }
}

TEST(SequentialTest, MakeMlpBuildsTheCartPoleNetwork) {
  std::mt19937 rng(0);
  Sequential net = MakeMlp(4, {120, 84}, 2, &rng);
  EXPECT_EQ(net.Architecture(), kCartPoleArch);
  EXPECT_EQ(net.NumParams(), 4 * 120 + 120 + 120 * 84 + 84 + 84 * 2 + 2);
  EXPECT_EQ(net.InputSize(), 4);
  EXPECT_EQ(net.OutputSize(), 2);
  const std::vector<Param> params = net.Params();
  ASSERT_EQ(params.size(), 6u);
  EXPECT_EQ(params[0].name, "0.weight");
  EXPECT_EQ(params[1].name, "0.bias");
  EXPECT_EQ(params[2].name, "2.weight");
  EXPECT_EQ(params[5].name, "4.bias");
  EXPECT_EQ(params[2].value->rows(), 84);
  EXPECT_EQ(params[2].value->cols(), 120);
}

TEST(SequentialTest, ArchitectureRoundTripsThroughBuildFromArchitecture) {
  std::mt19937 rng(0);
  for (const std::string& arch :
       {std::string(kCartPoleArch), std::string("linear(3,5),tanh,linear(5,1)"),
        std::string("linear(7,7)")}) {
    const Sequential net = BuildFromArchitecture(arch, &rng);
    EXPECT_EQ(net.Architecture(), arch);
  }
  EXPECT_EQ(BuildFromArchitecture(" linear( 4 , 8 ) , relu ,linear(8,2)", &rng).Architecture(),
            "linear(4,8),relu,linear(8,2)");
}

TEST(SequentialTest, SameSeedBuildsIdenticalNetworks) {
  std::mt19937 rng_a(42);
  std::mt19937 rng_b(42);
  EXPECT_EQ(Flat(BuildFromArchitecture(kCartPoleArch, &rng_a)),
            Flat(MakeMlp(4, {120, 84}, 2, &rng_b)));
}

TEST(SequentialTest, MalformedArchitecturesThrowWithTheOffendingLayer) {
  const std::pair<std::string, std::string> cases[] = {
      {"", "no layers"},
      {"linear(4)", "needs linear(in,out)"},
      {"linear(4,8", "unbalanced"},
      {"linear(4,8))", "unbalanced"},
      {"conv(3,4)", "unknown layer 0 'conv'"},
      {"linear(4,8),relu(1)", "takes no arguments"},
      {"linear(4,8),,relu", "layer 1 is empty"},
      {"linear(4,-8)", "'-8' is not a positive integer"},
      {"linear(a,8)", "'a' is not a positive integer"},
      {"linear(4,8)x", "text after ')'"},
      {"linear(4,8),relu,linear(7,2)", "expects 7 inputs but the previous layer produces 8"},
  };
  ExpectRefused(cases);
}

// Strings from checkpoint files and weight messages: sizes that would overflow an int or
// allocate gigabytes are refused before anything is built (each one was undefined behaviour or a
// 16 GB allocation). Found by fuzz/fuzz_checkpoint.
TEST(SequentialTest, BuildFromArchitectureRefusesSizesBeyondItsLimits) {
  const std::pair<std::string, std::string> cases[] = {
      {"linear(65535,65535)", "more than 67108864 parameters"},
      {"linear(4,8),relu,linear(8,70000)", "70000 is above the limit of 65536"},
      {"conv2d(1,1,1,1,60000,4,4)", "an image of more than 67108864 values"},
      {"conv2d(1,1,3,1,0,60000,60000)", "an image of more than 67108864 values"},
      {"batchnorm2d(1,50000,50000)", "an image of more than 67108864 values"},
      {"maxpool2d(1,1,50000,50000),flatten,linear(1,1)", "an image of more than 67108864 values"},
  };
  ExpectRefused(cases);
  // The largest network of ours is far below the limits.
  std::mt19937 rng(1);
  EXPECT_NO_THROW(BuildFromArchitecture(
      "conv2d(4,32,8,4,0,84,84),relu,conv2d(32,64,4,2,0,20,20),relu,conv2d(64,64,3,1,0,9,9),relu,"
      "flatten,linear(3136,512),relu,linear(512,18)",
      &rng));
}

TEST(SequentialTest, GetFlatSetFlatRoundTrip) {
  std::mt19937 rng(1);
  Sequential a = MakeMlp(3, {5}, 2, &rng);
  Sequential b = MakeMlp(3, {5}, 2, &rng);
  const std::vector<float> flat_a = Flat(a);
  ASSERT_EQ(flat_a.size(), static_cast<size_t>(a.NumParams()));
  // Column-major weight of layer 0 first, then its bias.
  EXPECT_EQ(flat_a[1], a.Params()[0].value->data()[1]);
  EXPECT_EQ(flat_a[15], (*a.Params()[1].value)(0, 0));
  EXPECT_NE(Flat(b), flat_a);
  b.SetFlat(flat_a.data(), flat_a.size());
  EXPECT_EQ(Flat(b), flat_a);
  const Matrix x = RandomMatrix(3, 4, &rng);
  EXPECT_EQ(Matrix(a.Forward(x)), b.Forward(x));
}

TEST(SequentialTest, SetFlatRejectsTheWrongSize) {
  std::mt19937 rng(1);
  Sequential net = MakeMlp(3, {5}, 2, &rng);
  std::vector<float> flat = Flat(net);
  flat.push_back(0.0f);
  EXPECT_THROW(net.SetFlat(flat.data(), flat.size()), std::invalid_argument);
}

TEST(SequentialTest, CopyParamsFromCopiesValuesAndKeepsParamPointers) {
  std::mt19937 rng(2);
  Sequential online = MakeMlp(4, {8}, 2, &rng);
  Sequential target = MakeMlp(4, {8}, 2, &rng);
  const Matrix* before = target.Params()[0].value;
  target.CopyParamsFrom(online);
  EXPECT_EQ(Flat(target), Flat(online));
  EXPECT_EQ(target.Params()[0].value, before);
}

TEST(SequentialTest, CopyParamsFromAbortsOnADifferentArchitecture) {
  std::mt19937 rng(2);
  Sequential a = MakeMlp(4, {8}, 2, &rng);
  Sequential b = MakeMlp(4, {9}, 2, &rng);
  EXPECT_DEATH(a.CopyParamsFrom(b), "same architecture");
}

TEST(SequentialTest, SoftUpdateFromBlendsParameters) {
  std::mt19937 rng(3);
  Sequential online = MakeMlp(4, {8}, 2, &rng);
  Sequential target = MakeMlp(4, {8}, 2, &rng);
  const std::vector<float> a = Flat(target);
  const std::vector<float> b = Flat(online);
  target.SoftUpdateFrom(online, 0.25f);
  const std::vector<float> blended = Flat(target);
  for (size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(blended[i], 0.25f * b[i] + 0.75f * a[i], 1e-6f);
  target.SoftUpdateFrom(online, 1.0f);
  EXPECT_EQ(Flat(target), b);
}

TEST(SequentialTest, CopiesAreDeepAndIndependent) {
  std::mt19937 rng(4);
  Sequential net = MakeMlp(4, {8}, 2, &rng);
  Sequential copy(net);
  EXPECT_EQ(copy.Architecture(), net.Architecture());
  EXPECT_EQ(Flat(copy), Flat(net));
  copy.Params()[0].value->setZero();
  EXPECT_NE(Flat(copy), Flat(net));
  Sequential assigned;
  assigned = net;
  EXPECT_EQ(Flat(assigned), Flat(net));
  Sequential moved = std::move(assigned);
  EXPECT_EQ(Flat(moved), Flat(net));
}

TEST(SequentialTest, PredictAndArgmaxMatchTheBatchedForward) {
  std::mt19937 rng(5);
  Sequential net = MakeMlp(4, {120, 84}, 2, &rng);
  const Matrix x = RandomMatrix(4, 128, &rng, 2.0f);
  const Matrix q = net.Forward(x);
  for (int j = 0; j < x.cols(); ++j) {
    const Matrix& single = net.Predict(x.col(j).data(), 4);
    ASSERT_EQ(single.rows(), 2);
    ASSERT_EQ(single.cols(), 1);
    EXPECT_NEAR(single(0, 0), q(0, j), 1e-5f);
    EXPECT_NEAR(single(1, 0), q(1, j), 1e-5f);
    Eigen::Index best = 0;
    q.col(j).maxCoeff(&best);
    EXPECT_EQ(net.Argmax(x.col(j).data(), 4), best);
  }
}

TEST(SequentialTest, LayerInputGivesTheActivationsOfTheLastForwardPass) {
  // linear(2,3),relu,linear(3,2): the input of layer 2 is relu(W x + b), the ReLU fused.
  Sequential net;
  Matrix w(3, 2);
  w << 1, 0, 0, 1, 1, -1;
  net.Add(std::make_unique<Linear>(w, (Matrix(3, 1) << 0.5f, -4, 0).finished()));
  net.Add(std::make_unique<ReLU>());
  net.Add(std::make_unique<Linear>(Matrix::Ones(2, 3), Matrix::Zero(2, 1)));
  EXPECT_THROW(net.LayerInput(0), std::logic_error);  // no forward pass yet
  EXPECT_THROW(net.LayerInput(3), std::out_of_range);
  EXPECT_THROW(net.LayerInput(-1), std::out_of_range);

  const float obs[2] = {1.0f, 3.0f};
  const Matrix& q = net.Predict(obs, 2);
  const Matrix& hidden = net.LayerInput(2);
  ASSERT_EQ(hidden.rows(), 3);
  ASSERT_EQ(hidden.cols(), 1);
  EXPECT_FLOAT_EQ(hidden(0, 0), 1.5f);  // 1 + 0.5
  EXPECT_FLOAT_EQ(hidden(1, 0), 0.0f);  // relu(3 - 4)
  EXPECT_FLOAT_EQ(hidden(2, 0), 0.0f);  // relu(1 - 3)
  EXPECT_FLOAT_EQ(q(0, 0), 1.5f);
  // Layer 1 (the fused ReLU) sees the same activations; layer 0 the observation.
  EXPECT_EQ(net.LayerInput(1), hidden);
  EXPECT_FLOAT_EQ(net.LayerInput(0)(0, 0), 1.0f);
  EXPECT_FLOAT_EQ(net.LayerInput(0)(1, 0), 3.0f);

  // A batched forward pass replaces them.
  Matrix x(2, 2);
  x << 2, 0, 0, 5;
  net.Forward(x);
  const Matrix& batch = net.LayerInput(2);
  ASSERT_EQ(batch.cols(), 2);
  EXPECT_FLOAT_EQ(batch(0, 0), 2.5f);
  EXPECT_FLOAT_EQ(batch(2, 0), 2.0f);
  EXPECT_FLOAT_EQ(batch(1, 1), 1.0f);  // 5 - 4
  EXPECT_FLOAT_EQ(batch(2, 1), 0.0f);  // relu(-5)
}

TEST(SequentialTest, ArgmaxPicksTheFirstOfTiedMaxima) {
  Sequential net;
  net.Add(std::make_unique<Linear>(Matrix::Zero(3, 2), (Matrix(3, 1) << 1, 3, 3).finished()));
  const float obs[2] = {0.5f, -0.5f};
  EXPECT_EQ(net.Argmax(obs, 2), 1);
}

TEST(SequentialTest, AddRejectsMismatchedLayerSizes) {
  std::mt19937 rng(0);
  Sequential net;
  net.Add(std::make_unique<Linear>(4, 8, &rng));
  net.Add(std::make_unique<ReLU>());
  EXPECT_THROW(net.Add(std::make_unique<Linear>(7, 2, &rng)), std::invalid_argument);
}

// Back-propagates the gathered-action loss of DQN (the loss only sees Q(s_j, a_j)) through `net`
// on a random batch of 5 and expects the gradients of the input and of every parameter to match
// finite differences. Huber (delta 1) or mean squared error, with random sample weights in
// [0.5, 1.5] or none.
void ExpectGatheredLossGradientsMatch(Sequential* net, const std::array<int, 5>& actions,
                                      bool huber, bool weighted, std::mt19937* rng) {
  const int batch = static_cast<int>(actions.size());
  Matrix x = RandomMatrix(net->InputSize(), batch, rng, 2.0f);
  const Vector target = RandomMatrix(batch, 1, rng, 2.0f);
  Vector weights;
  if (weighted) weights = RandomMatrix(batch, 1, rng, 0.5f).array() + 1.0f;
  const Vector* w = weighted ? &weights : nullptr;
  Vector pred(batch);
  auto loss_with_grad = [&](Vector* grad) {
    const Matrix& q = net->Forward(x);
    for (int j = 0; j < batch; ++j) pred[j] = q(actions[j], j);
    return huber ? HuberLoss(pred, target, grad, 1.0f, w) : MseLoss(pred, target, grad, w);
  };
  auto loss = [&] { return static_cast<double>(loss_with_grad(nullptr)); };

  Vector grad;
  loss_with_grad(&grad);
  Matrix grad_q = Matrix::Zero(net->OutputSize(), batch);
  for (int j = 0; j < batch; ++j) grad_q(actions[j], j) = grad[j];
  net->ZeroGrad();
  const Matrix dx = net->Backward(grad_q);

  ExpectGradientsClose(dx, NumericalGradient(loss, &x), "input");
  for (const Param& p : net->Params()) {
    const Matrix analytic = *p.grad;
    ExpectGradientsClose(analytic, NumericalGradient(loss, p.value), p.name);
  }
}

// Through an MLP, with weighted samples.
void CheckEndToEndGradients(bool huber) {
  std::mt19937 rng(13);
  Sequential net = MakeMlp(3, {8, 6}, 2, &rng);
  ExpectGatheredLossGradientsMatch(&net, {0, 1, 1, 0, 1}, huber, /*weighted=*/true, &rng);
}

TEST(SequentialTest, MlpGradientsThroughWeightedHuberMatchFiniteDifferences) {
  CheckEndToEndGradients(/*huber=*/true);
}

TEST(SequentialTest, MlpGradientsThroughWeightedMseMatchFiniteDifferences) {
  CheckEndToEndGradients(/*huber=*/false);
}

// Runs clones of net's layers one by one (clones are never fused) on a random batch and expects
// the same outputs, input gradients and parameter gradients as the (fused) network.
void ExpectSameAsUnfusedLayers(Sequential* net, int batch, float grad_tolerance,
                               std::mt19937* rng) {
  std::vector<std::unique_ptr<Layer>> layers;
  for (int i = 0; i < net->num_layers(); ++i) layers.push_back(net->layer(i).Clone());
  const Matrix x = RandomMatrix(net->InputSize(), batch, rng);
  const Matrix grad_out = RandomMatrix(net->OutputSize(), batch, rng);

  const Matrix* h = &x;
  for (auto& layer : layers) h = &layer->Forward(*h);
  const Matrix* g = &grad_out;
  for (size_t i = layers.size(); i-- > 0;) g = &layers[i]->Backward(*g);

  EXPECT_TRUE(net->Forward(x).isApprox(*h, 1e-5f));
  net->ZeroGrad();
  EXPECT_TRUE(net->Backward(grad_out).isApprox(*g, 1e-5f));
  std::vector<Param> expected;
  for (auto& layer : layers) {
    for (const Param& p : layer->Params()) expected.push_back(p);
  }
  const std::vector<Param> got = net->Params();
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i) {
    EXPECT_TRUE(got[i].grad->isApprox(*expected[i].grad, grad_tolerance)) << got[i].name;
  }
}

// Sequential fuses ReLUs into neighbouring Linear layers; running clones of the same layers one
// by one (clones are never fused) must give the same outputs and gradients.
TEST(SequentialTest, FusedReluGivesTheSameResultsAsSeparateLayers) {
  std::mt19937 rng(21);
  for (const std::string& arch : {std::string("linear(5,40),relu,linear(40,33),relu,linear(33,3)"),
                                  std::string("relu,linear(5,9),relu,linear(9,4),relu")}) {
    for (int batch : {1, 3, 16, 37}) {
      SCOPED_TRACE(arch + " batch " + std::to_string(batch));
      Sequential net = BuildFromArchitecture(arch, &rng);
      ExpectSameAsUnfusedLayers(&net, batch, 1e-5f, &rng);
    }
  }
}

TEST(SequentialTest, BackwardParamsAccumulatesTheSameGradientsAsBackward) {
  std::mt19937 rng(8);
  for (const std::string& arch : {std::string(kCartPoleArch), std::string("relu,linear(4,9)")}) {
    SCOPED_TRACE(arch);
    Sequential net = BuildFromArchitecture(arch, &rng);
    Sequential copy = net;
    const Matrix x = RandomMatrix(4, 32, &rng);
    const Matrix grad_out = RandomMatrix(net.OutputSize(), 32, &rng);
    net.Forward(x);
    net.Backward(grad_out);
    copy.Forward(x);
    copy.BackwardParams(grad_out);
    copy.BackwardParams(grad_out);
    const std::vector<Param> expected = net.Params();
    const std::vector<Param> got = copy.Params();
    for (size_t i = 0; i < got.size(); ++i) {
      EXPECT_TRUE(got[i].grad->isApprox(2 * *expected[i].grad, 1e-5f)) << got[i].name;
    }
  }
}

TEST(SequentialTest, ZeroGradClearsAllGradients) {
  std::mt19937 rng(6);
  Sequential net = MakeMlp(3, {4}, 2, &rng);
  const Matrix x = RandomMatrix(3, 2, &rng);
  net.Forward(x);
  net.Backward(Matrix::Ones(2, 2));
  EXPECT_FALSE(net.Params()[0].grad->isZero());
  net.ZeroGrad();
  for (const Param& p : net.Params()) EXPECT_TRUE(p.grad->isZero()) << p.name;
}

// A small network with every kind of layer: 2 x 7 x 7 images -> 3 Q values.
constexpr char kConvArch[] =
    "conv2d(2,4,3,2,1,7,7),batchnorm2d(4,4,4),relu,conv2d(4,3,2,1,0,4,4),relu,flatten,"
    "layernorm(27),linear(27,8),tanh,dueling(8,5,3)";

TEST(SequentialTest, ArchitecturesWithEveryLayerKindRoundTrip) {
  std::mt19937 rng(30);
  const Sequential net = BuildFromArchitecture(kConvArch, &rng);
  EXPECT_EQ(net.Architecture(), kConvArch);
  EXPECT_EQ(net.InputSize(), 2 * 7 * 7);
  EXPECT_EQ(net.OutputSize(), 3);
  EXPECT_EQ(BuildFromArchitecture(" conv2d( 1, 2, 3, 1, 1, 4, 4 ) , flatten , linear(32,2)", &rng)
                .Architecture(),
            "conv2d(1,2,3,1,1,4,4),flatten,linear(32,2)");
}

TEST(SequentialTest, MalformedConvolutionalArchitecturesThrowWithTheOffendingLayer) {
  const std::pair<std::string, std::string> cases[] = {
      {"conv2d(4,32,8,4,0,84)", "needs conv2d(in_channels,out_channels,kernel,stride,padding,"},
      {"conv2d(4,32,8,4,-1,84,84)", "'-1' is not a non-negative integer"},
      {"conv2d(4,32,0,4,0,84,84)", "'0' is not a positive integer"},
      {"conv2d(4,32,90,1,0,84,84)", "kernel is larger than the padded input"},
      {"batchnorm2d(32,9)", "needs batchnorm2d(channels,height,width)"},
      {"flatten(1)", "takes no arguments"},
      {"layernorm()", "needs layernorm(features), got 0 arguments"},
      {"dueling(10,0,3)", "'0' is not a positive integer"},
      {"conv2d(1,2,3,1,0,5,5),batchnorm2d(3,3,3)", "expects 27 inputs"},
      {"conv2d(4,32,8,4,0,84,84),relu,conv2d(16,64,4,2,0,40,20)",
       "expects 16x40x20 images but the previous layers produce 32x20x20"},
      {"maxpool(2)", "unknown layer 0 'maxpool' (known: linear(in,out), conv2d("},
  };
  ExpectRefused(cases);
}

TEST(SequentialTest, BuffersFollowTheParametersInGetFlat) {
  std::mt19937 rng(31);
  Sequential net = BuildFromArchitecture(kConvArch, &rng);
  const std::vector<Buffer> buffers = net.Buffers();
  ASSERT_EQ(buffers.size(), 2u);
  EXPECT_EQ(buffers[0].name, "1.running_mean");
  EXPECT_EQ(buffers[1].name, "1.running_var");
  EXPECT_EQ(net.NumBuffers(), 8);
  EXPECT_EQ(net.FlatSize(), net.NumParams() + 8);
  // Params() holds trainable tensors only.
  for (const Param& p : net.Params()) EXPECT_EQ(p.name.find("running"), std::string::npos);

  // Move the running statistics away from their initial values, then check the flat layout.
  net.Forward(RandomMatrix(net.InputSize(), 6, &rng));
  const std::vector<float> flat = Flat(net);
  ASSERT_EQ(flat.size(), static_cast<size_t>(net.FlatSize()));
  const auto at = static_cast<size_t>(net.NumParams());
  for (int c = 0; c < 4; ++c) {
    EXPECT_EQ(flat[at + c], (*buffers[0].value)(c, 0));
    EXPECT_EQ(flat[at + 4 + c], (*buffers[1].value)(c, 0));
  }
  EXPECT_NE(flat[at], 0.0f);

  // SetFlat restores parameters and buffers; a wrong size names both counts.
  Sequential other = BuildFromArchitecture(kConvArch, &rng);
  other.SetFlat(flat.data(), flat.size());
  EXPECT_EQ(Flat(other), flat);
  EXPECT_EQ(*other.Buffers()[1].value, *buffers[1].value);
  try {
    other.SetFlat(flat.data(), static_cast<size_t>(net.NumParams()));
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("and 8 buffer floats"), std::string::npos) << e.what();
  }
}

TEST(SequentialTest, CopyAndSoftUpdateIncludeBuffers) {
  std::mt19937 rng(32);
  Sequential online = BuildFromArchitecture(kConvArch, &rng);
  Sequential target = BuildFromArchitecture(kConvArch, &rng);
  online.Forward(RandomMatrix(online.InputSize(), 6, &rng));
  const Matrix online_mean = *online.Buffers()[0].value;
  target.SoftUpdateFrom(online, 0.5f);
  EXPECT_TRUE(target.Buffers()[0].value->isApprox(0.5f * online_mean, 1e-6f));
  target.CopyParamsFrom(online);
  EXPECT_EQ(Flat(target), Flat(online));
}

TEST(SequentialTest, EvalModeUsesRunningStatisticsAndPredictAlwaysDoes) {
  std::mt19937 rng(33);
  Sequential net = BuildFromArchitecture(kConvArch, &rng);
  EXPECT_TRUE(net.training());
  const Matrix batch = RandomMatrix(net.InputSize(), 8, &rng, 2.0f);
  for (int i = 0; i < 5; ++i) net.Forward(batch);
  const Matrix one = batch.col(3);

  // Training mode: the statistics of the batch, which for one sample differ from the running
  // ones, and every forward pass moves the running statistics.
  const Matrix train_batch_q = net.Forward(batch);
  const std::vector<float> before = Flat(net);
  net.set_training(false);
  EXPECT_FALSE(net.training());
  const Matrix eval_q = net.Forward(one);
  EXPECT_EQ(Flat(net), before);
  EXPECT_GT((eval_q.col(0) - train_batch_q.col(3)).cwiseAbs().maxCoeff(), 1e-4f);

  // Predict() gives the eval-mode result even in training mode, and leaves the buffers alone.
  net.set_training(true);
  const Matrix& predicted = net.Predict(one.data(), static_cast<int>(one.size()));
  EXPECT_TRUE(predicted.isApprox(eval_q, 1e-5f));
  EXPECT_EQ(Flat(net), before);
  EXPECT_TRUE(net.training());
  net.Forward(batch);
  EXPECT_NE(Flat(net), before);

  // Copies keep the mode.
  net.set_training(false);
  const Sequential copy = net;
  EXPECT_FALSE(copy.training());
}

// Back-propagates a gathered-action Huber loss through the network with every layer kind.
TEST(SequentialTest, ConvNetGradientsThroughHuberMatchFiniteDifferences) {
  std::mt19937 rng(34);
  Sequential net = BuildFromArchitecture(kConvArch, &rng);
  ExpectGatheredLossGradientsMatch(&net, {0, 2, 1, 1, 2}, /*huber=*/true, /*weighted=*/false, &rng);
}

// ReLUs fused into convolutions, batch normalisation and the dueling head give the same results
// as running unfused clones layer by layer.
TEST(SequentialTest, FusedReluInConvNetsGivesTheSameResultsAsSeparateLayers) {
  std::mt19937 rng(35);
  for (const std::string& arch :
       {std::string("conv2d(2,4,3,1,1,6,6),relu,conv2d(4,3,3,2,0,6,6),relu,flatten,linear(12,2)"),
        std::string("conv2d(2,4,3,2,1,6,6),batchnorm2d(4,3,3),relu,conv2d(4,5,2,1,0,3,3),relu,"
                    "flatten,relu,dueling(20,6,3)")}) {
    for (int batch : {2, 9}) {
      SCOPED_TRACE(arch + " batch " + std::to_string(batch));
      Sequential net = BuildFromArchitecture(arch, &rng);
      ExpectSameAsUnfusedLayers(&net, batch, 1e-4f, &rng);
    }
  }
}

}  // namespace
}  // namespace rl::nn
