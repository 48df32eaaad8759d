// The check both direct decoders' tests make (png_decoding_test.cpp, jpeg_decoding_test.cpp):
// under every flag they take, the decoder takes the file and gives cv::imdecode's type and
// pixels.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

namespace pnpba::test {

using DirectDecoder = bool (*)(const unsigned char*, size_t, int, cv::Mat*);

inline void expectDecodedAsOpenCv(DirectDecoder decode, const std::vector<unsigned char>& bytes,
                                  const std::string& what) {
  const int flag_list[] = {cv::IMREAD_UNCHANGED, cv::IMREAD_GRAYSCALE, cv::IMREAD_COLOR,
                           cv::IMREAD_ANYDEPTH, cv::IMREAD_ANYDEPTH | cv::IMREAD_COLOR};
  for (int flags : flag_list) {
    SCOPED_TRACE(what + ", flags " + std::to_string(flags));
    const cv::Mat expected = cv::imdecode(bytes, flags);
    ASSERT_FALSE(expected.empty());
    cv::Mat got;
    ASSERT_TRUE(decode(bytes.data(), bytes.size(), flags, &got));
    ASSERT_EQ(got.type(), expected.type());
    ASSERT_EQ(got.size(), expected.size());
    EXPECT_EQ(cv::norm(got, expected, cv::NORM_INF), 0);
  }
}

}  // namespace pnpba::test
