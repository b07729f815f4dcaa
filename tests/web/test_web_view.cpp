// The web view's server without a viz: pictures, status and keys over real HTTP on loopback
// (cpp-httplib's client), and the addresses a user writes.

#include <gtest/gtest.h>
#include <httplib.h>

#include <atomic>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <thread>

#include "evldt/web/web_view.hpp"

namespace evldt {
namespace {

TEST(HttpAddress, PortAloneHostAndPortAndIpv6) {
  EXPECT_EQ(parse_http_address("8080").host, "0.0.0.0");
  EXPECT_EQ(parse_http_address("8080").port, 8080);
  EXPECT_EQ(parse_http_address(":8081").port, 8081);
  EXPECT_EQ(parse_http_address(":8081").host, "0.0.0.0");
  EXPECT_EQ(parse_http_address("127.0.0.1:0").host, "127.0.0.1");
  EXPECT_EQ(parse_http_address("127.0.0.1:0").port, 0);
  EXPECT_EQ(parse_http_address("[::1]:9000").host, "::1");
  EXPECT_EQ(parse_http_address("[::1]:9000").port, 9000);
  for (const char* bad : {"", "http", "host:", "127.0.0.1:x", "65536", "-1", "1:2:3x", "80 "}) {
    EXPECT_THROW(parse_http_address(bad), std::invalid_argument) << bad;
  }
}

WebViewOptions on_loopback(int port, std::string title = "evldt") {
  WebViewOptions options;
  options.address = {"127.0.0.1", port};
  options.title = std::move(title);
  return options;
}

std::vector<WebLayer> layers() { return {{'e', "events", true}, {'g', "block grid", false}}; }

/// A picture of one colour per number, to tell pictures apart after JPEG.
cv::Mat picture_of(int shade) { return cv::Mat(90, 120, CV_8UC3, cv::Scalar(shade, 255 - shade, 40)); }

struct WebViewTest : ::testing::Test {
  WebView view{on_loopback(0, "evldt <test>")};
  httplib::Client client{"127.0.0.1", view.port()};
};

TEST_F(WebViewTest, ServesThePageWithItsTitleEscaped) {
  const auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<title>evldt &lt;test&gt;</title>"), std::string::npos);
  EXPECT_EQ(client.Get("/nothing")->status, 404);
  EXPECT_EQ(view.counts().pages, 1u);
}

TEST_F(WebViewTest, CopiesPicturesOnlyWhileABrowserLooks) {
  EXPECT_FALSE(view.watched());
  view.publish(picture_of(10), {"status one"}, layers());
  // Drawn while nobody looked: not copied, so nothing to send yet; the request starts the watch.
  EXPECT_EQ(client.Get("/picture.jpg")->status, 204);
  EXPECT_TRUE(view.watched());
  view.publish(picture_of(200), {"status two"}, layers());
  const auto picture = client.Get("/picture.jpg");
  ASSERT_TRUE(picture);
  ASSERT_EQ(picture->status, 200);
  EXPECT_EQ(picture->get_header_value("Content-Type"), "image/jpeg");
  EXPECT_EQ(picture->get_header_value("X-Picture"), "2");
  const cv::Mat decoded =
      cv::imdecode(std::vector<std::uint8_t>(picture->body.begin(), picture->body.end()), cv::IMREAD_COLOR);
  ASSERT_EQ(decoded.size(), cv::Size(120, 90));
  const cv::Vec3b centre = decoded.at<cv::Vec3b>(45, 60);
  EXPECT_NEAR(centre[0], 200, 4);
  EXPECT_NEAR(centre[1], 55, 4);
  // The browser shows picture 2: nothing newer until the next is published.
  EXPECT_EQ(client.Get("/picture.jpg?after=2")->status, 204);
  EXPECT_EQ(client.Get("/picture.jpg?after=x")->status, 400);
  EXPECT_EQ(view.counts().pictures, 1u);
}

TEST_F(WebViewTest, EachPictureIsEncodedOnceAndKeepsItsOwnPixelsWhileHeld) {
  ASSERT_EQ(client.Get("/picture.jpg")->status, 204);  // watch
  std::uint64_t number = 0;
  for (int shade = 0; shade <= 250; shade += 50) {
    view.publish(picture_of(shade), {}, layers());
    ++number;
    // Two browsers fetch the same picture: one encoding.
    for (int browser = 0; browser < 2; ++browser) {
      const auto picture = client.Get("/picture.jpg");
      ASSERT_EQ(picture->status, 200);
      EXPECT_EQ(picture->get_header_value("X-Picture"), std::to_string(number));
      const cv::Mat decoded =
          cv::imdecode(std::vector<std::uint8_t>(picture->body.begin(), picture->body.end()), cv::IMREAD_COLOR);
      EXPECT_NEAR(decoded.at<cv::Vec3b>(10, 10)[0], shade, 4) << "picture " << number;
    }
  }
  EXPECT_EQ(view.counts().encoded, number);
  EXPECT_EQ(view.counts().pictures, 2 * number);
}

TEST_F(WebViewTest, StatusJsonHasTheNewestStatusAndLayersEscaped) {
  view.publish(picture_of(0), {"cam0  t=1.000 s", "a \"quoted\" \\ field"}, layers());
  const auto status = client.Get("/status.json");
  ASSERT_EQ(status->status, 200);
  EXPECT_EQ(status->body,
            R"({"picture": 1, "status": ["cam0  t=1.000 s", "a \"quoted\" \\ field"], "layers": [)"
            R"({"key": "e", "name": "events", "shown": true}, {"key": "g", "name": "block grid", "shown": false}]})");
}

TEST_F(WebViewTest, KeysOfTheLayersAreQueuedInOrderOthersRefused) {
  EXPECT_EQ(client.Post("/key/g", "", "text/plain")->status, 404);  // no picture yet: no layers
  view.publish(picture_of(0), {}, layers());
  EXPECT_EQ(client.Post("/key/g", "", "text/plain")->status, 204);
  EXPECT_EQ(client.Post("/key/e", "", "text/plain")->status, 204);
  EXPECT_EQ(client.Post("/key/z", "", "text/plain")->status, 404);
  EXPECT_EQ(view.take_keys(), (std::vector<char>{'g', 'e'}));
  EXPECT_TRUE(view.take_keys().empty());
  for (std::size_t i = 0; i < WebView::kMaxQueuedKeys; ++i)
    ASSERT_EQ(client.Post("/key/e", "", "text/plain")->status, 204);
  EXPECT_EQ(client.Post("/key/e", "", "text/plain")->status, 503);  // the viz is not taking them
  EXPECT_EQ(view.take_keys().size(), WebView::kMaxQueuedKeys);
  EXPECT_EQ(view.counts().keys, 2 + WebView::kMaxQueuedKeys);
}

// The viz reuses the picture before the newest once no browser holds it: browsers reading status
// and pictures while it publishes must never see one being rewritten (run under ThreadSanitizer,
// which reported the reuse of a picture a browser had read last without ordering).
TEST_F(WebViewTest, BrowsersReadingWhileTheVizPublishesSeeWholePictures) {
  std::atomic<bool> done{false};
  std::atomic<int> answers{0}, torn{0};
  const auto browse = [&] {
    httplib::Client browser{"127.0.0.1", view.port()};
    while (!done.load()) {
      if (const auto status = browser.Get("/status.json"); status && status->status == 200) {
        ++answers;
        // Every picture's status lines are one number twice: a mix of two pictures is torn.
        const std::string& body = status->body;
        const auto first = body.find("\"n="), second = body.find("\"n=", first + 1);
        if (first != std::string::npos &&
            (second == std::string::npos || body.substr(first, body.find('"', first + 1) - first) !=
                                                body.substr(second, body.find('"', second + 1) - second))) {
          ++torn;
        }
      }
      if (const auto picture = browser.Get("/picture.jpg"); picture && picture->status == 200) ++answers;
    }
  };
  std::thread first(browse), second(browse);
  for (int n = 0; n < 400 || answers.load() < 50; ++n) {
    const std::string line = "n=" + std::to_string(n);
    view.publish(picture_of(n % 256), {line, line}, layers());
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    ASSERT_LT(n, 200000) << "the browsers got no answers";
  }
  done = true;
  first.join();
  second.join();
  EXPECT_EQ(torn.load(), 0);
}

TEST(WebView, APortInUseIsAnErrorNamingIt) {
  const WebView first(on_loopback(0));
  try {
    const WebView second(on_loopback(first.port()));
    FAIL() << "bound a port in use";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("127.0.0.1:" + std::to_string(first.port())), std::string::npos)
        << error.what();
  }
  EXPECT_EQ(first.url(), "http://127.0.0.1:" + std::to_string(first.port()) + "/");
}

}  // namespace
}  // namespace evldt
