#include "evldt/events/event_writer.hpp"

#include <stdexcept>
#include <string>

namespace evldt {

namespace detail {

void check_encodable(const EventBatch& batch, Timestamp previous_time, int max_coordinate, std::string_view format) {
  for (std::size_t i = 0; i < batch.size(); ++i) {
    if (batch.t[i] < 0)
      throw std::invalid_argument("cannot encode the negative time " + std::to_string(batch.t[i]) + " us");
    if (batch.t[i] < previous_time) {
      throw std::invalid_argument("events must be written in time order: event at " + std::to_string(batch.t[i]) +
                                  " us comes after one at " + std::to_string(previous_time) + " us");
    }
    previous_time = batch.t[i];
    if (batch.x[i] > max_coordinate || batch.y[i] > max_coordinate) {
      throw std::invalid_argument(std::string(format) + " cannot encode pixel (" + std::to_string(batch.x[i]) + ", " +
                                  std::to_string(batch.y[i]) + "): coordinates go up to " +
                                  std::to_string(max_coordinate));
    }
  }
}

void write_raw_header(std::string_view encoding, SensorSize sensor, std::vector<std::uint8_t>& out) {
  const std::string width = std::to_string(sensor.width);
  const std::string height = std::to_string(sensor.height);
  // "% evt 2.0" / "% evt 3.0" for older readers; EVT 2.1 is named only by its format line, with the
  // byte order of its 64-bit words.
  const std::string evt_line = encoding == "EVT21" ? "" : "% evt " + std::string(encoding.substr(3)) + ".0\n";
  const std::string options = encoding == "EVT21" ? ";endianness=little" : "";
  const std::string header = evt_line + "% format " + std::string(encoding) + options + ";height=" + height +
                             ";width=" + width + "\n% geometry " + width + "x" + height + "\n% end\n";
  out.insert(out.end(), header.begin(), header.end());
}

}  // namespace detail

std::unique_ptr<EventEncoder> make_encoder(EventFormat format, SensorSize sensor) {
  switch (format) {
    case EventFormat::EcdText:
      return detail::make_ecd_text_encoder();
    case EventFormat::Evt2:
      return detail::make_evt2_encoder(sensor);
    case EventFormat::Evt3:
      return detail::make_evt3_encoder(sensor);
    case EventFormat::Evt21:
      return detail::make_evt21_encoder(sensor);
    case EventFormat::Dat:
      return detail::make_dat_encoder(sensor);
    case EventFormat::Aedat2:
    case EventFormat::Aedat31:
    case EventFormat::Aedat31Network:
    case EventFormat::EventStream:
      throw std::invalid_argument("evldt reads " + std::string(format_name(format)) + " but does not write it");
  }
  throw std::invalid_argument("unknown event format");
}

EventWriter::EventWriter(const std::filesystem::path& path, EventFormat format, SensorSize sensor)
    : path_(path), encoder_(make_encoder(format, sensor)), file_(path, std::ios::binary | std::ios::trunc) {
  if (!file_) throw std::runtime_error("cannot create event file '" + path_.string() + "'");
  encoder_->write_header(buffer_);
  file_.write(reinterpret_cast<const char*>(buffer_.data()), static_cast<std::streamsize>(buffer_.size()));
  check_stream("write the header of");
}

EventWriter::~EventWriter() {
  if (file_.is_open()) file_.close();
}

void EventWriter::write(const EventBatch& batch) {
  if (!file_.is_open()) throw std::logic_error("event file '" + path_.string() + "' written after close()");
  buffer_.clear();
  encoder_->encode(batch, buffer_);
  file_.write(reinterpret_cast<const char*>(buffer_.data()), static_cast<std::streamsize>(buffer_.size()));
  check_stream("write to");
}

void EventWriter::close() {
  if (!file_.is_open()) return;
  file_.flush();
  check_stream("flush");
  file_.close();
  check_stream("close");
}

void EventWriter::check_stream(const char* doing) const {
  if (!file_) throw std::runtime_error(std::string("cannot ") + doing + " event file '" + path_.string() + "'");
}

}  // namespace evldt
