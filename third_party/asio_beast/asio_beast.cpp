// The compiled parts of Boost.Asio and Boost.Beast, built once (library
// sky_asio_beast, cmake/build_speed.cmake) instead of inline in every
// translation unit that includes them. Every target that links sky::asio is
// compiled with BOOST_ASIO_SEPARATE_COMPILATION and
// BOOST_BEAST_SEPARATE_COMPILATION and links this library; nothing else
// belongs in this file.
#include <boost/asio/impl/src.hpp>
#include <boost/beast/src.hpp>
