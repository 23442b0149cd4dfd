// The real ComediApi: one forwarding call per comedilib function. The only file that includes
// comedilib.h.
#include <comedilib.h>

#include "crane/hardware_bridge/comedi_board.hpp"

namespace crane::hardware_bridge {

static_assert(static_cast<int>(ComediSubdeviceType::analog_output) == COMEDI_SUBD_AO);
static_assert(static_cast<int>(ComediSubdeviceType::digital_input) == COMEDI_SUBD_DI);
static_assert(static_cast<int>(ComediSubdeviceType::digital_output) == COMEDI_SUBD_DO);
static_assert(static_cast<int>(ComediSubdeviceType::digital_io) == COMEDI_SUBD_DIO);
static_assert(static_cast<int>(ComediSubdeviceType::counter) == COMEDI_SUBD_COUNTER);
static_assert(kComediUnitVolt == UNIT_volt);
static_assert(kComediAnalogRefGround == AREF_GROUND);
static_assert(kComediDioInput == COMEDI_INPUT && kComediDioOutput == COMEDI_OUTPUT);

namespace {

comedi_t* native(ComediDevice* device) noexcept { return reinterpret_cast<comedi_t*>(device); }

class ComedilibApi final : public ComediApi {
 public:
  ComediDevice* open(const std::string& device_path) override {
    return reinterpret_cast<ComediDevice*>(comedi_open(device_path.c_str()));
  }
  int close(ComediDevice* device) override { return comedi_close(native(device)); }
  int get_subdevice_type(ComediDevice* device, unsigned subdevice) override {
    return comedi_get_subdevice_type(native(device), subdevice);
  }
  int get_n_channels(ComediDevice* device, unsigned subdevice) override {
    return comedi_get_n_channels(native(device), subdevice);
  }
  std::uint32_t get_maxdata(ComediDevice* device, unsigned subdevice, unsigned channel) override {
    return comedi_get_maxdata(native(device), subdevice, channel);
  }
  bool get_range(ComediDevice* device, unsigned subdevice, unsigned channel, unsigned range_index,
                 ComediRange& range) override {
    const comedi_range* found = comedi_get_range(native(device), subdevice, channel, range_index);
    if (found == nullptr) return false;
    range.min = found->min;
    range.max = found->max;
    range.unit = found->unit;
    return true;
  }
  int data_read(ComediDevice* device, unsigned subdevice, unsigned channel, unsigned range_index, unsigned aref,
                std::uint32_t& data) override {
    lsampl_t value = 0;
    const int result = comedi_data_read(native(device), subdevice, channel, range_index, aref, &value);
    data = value;
    return result;
  }
  int data_write(ComediDevice* device, unsigned subdevice, unsigned channel, unsigned range_index, unsigned aref,
                 std::uint32_t data) override {
    return comedi_data_write(native(device), subdevice, channel, range_index, aref, data);
  }
  int dio_config(ComediDevice* device, unsigned subdevice, unsigned channel, unsigned direction) override {
    return comedi_dio_config(native(device), subdevice, channel, direction);
  }
  int dio_bitfield2(ComediDevice* device, unsigned subdevice, unsigned write_mask, unsigned& bits,
                    unsigned base_channel) override {
    return comedi_dio_bitfield2(native(device), subdevice, write_mask, &bits, base_channel);
  }
  int error_number() override { return comedi_errno(); }
  std::string error_string(int error_number) override {
    const char* text = comedi_strerror(error_number);
    return text != nullptr ? std::string(text) : std::string("unknown error");
  }
};

}  // namespace

std::unique_ptr<ComediApi> make_comedilib_api() { return std::make_unique<ComedilibApi>(); }

}  // namespace crane::hardware_bridge
