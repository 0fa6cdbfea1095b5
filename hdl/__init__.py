"""MyHDL blocks, in rooms by family (docs/architecture.md): interfaces, common, streaming, harris, rectify,
camera, memory, axi, dense, matching, video, serial, system; board tops in ``boards``; the EDA flow in ``flow`` (it
imports the blocks, no block imports it).

The public blocks and port bundles are re-exported here, so a user's import stays short::

    from eyestereo.hdl import harris_mono, ImageStream

They load on first use (PEP 562), so ``import eyestereo.hdl`` stays cheap and no block depends on this list.
"""

from eyestereo.hdl.common.callinfo import install as _install_callinfo

# MyHDL's elaboration reads the whole call stack for every block; see eyestereo.hdl.common.callinfo.
_install_callinfo()

#: public name -> the module (under eyestereo.hdl) that defines it: every catalogue block function and
#: the port bundles its ports are made of
_EXPORTS = {
    # blocks
    "line_delay": "streaming.line_delay",
    "convolve": "streaming.convolve",
    "stream_checker": "streaming.stream_checker",
    "async_fifo": "streaming.async_fifo",
    "stream_cdc": "streaming.stream_cdc",
    "word_cdc": "streaming.word_cdc",
    "sobel": "harris.sobel",
    "harris_window": "harris.harris_window",
    "cornerness": "harris.cornerness",
    "prethreshold": "harris.prethreshold",
    "nms": "harris.nms",
    "census": "dense.census",
    "sgm": "dense.sgm",
    "median3": "dense.median3",
    "dense_stereo": "dense.dense_stereo",
    "corner_descriptors": "matching.corner_descriptors",
    "match_engine": "matching.match_engine",
    "feature_matcher": "matching.feature_matcher",
    "list_append": "system.list_append",
    "harris_mono": "harris.harris_mono",
    "harris_stereo": "harris.harris_stereo",
    "feature_list": "harris.feature_list",
    "poly_unit": "rectify.poly_unit",
    "coordinate_warper": "rectify.coordinate_warper",
    "fetch_interpolate": "rectify.fetch_interpolate",
    "rectifier": "rectify.rectifier",
    "line_cache": "rectify.line_cache",
    "stream_rectifier": "rectify.stream_rectifier",
    "camera_stream": "camera.camera_stream",
    "camera_interface": "camera.camera_interface",
    "camera_pair": "camera.camera_interface",
    "sccb_master": "camera.sccb_master",
    "sram_controller": "memory.sram_controller",
    "sram_arbiter": "memory.sram_arbiter",
    "sram_subsystem": "memory.sram_subsystem",
    "sdram_controller": "memory.sdram_controller",
    "sdram_bridge": "memory.sdram_bridge",
    "sdram_subsystem": "memory.sdram_subsystem",
    "double_buffer": "memory.frame_buffers",
    "axis_to_stream": "axi.axis_to_stream",
    "stream_to_axis": "axi.stream_to_axis",
    "axil_arbiter": "axi.axil_arbiter",
    "axil_split": "axi.axil_split",
    "register_bank": "system.register_bank",
    "stereo_frontend": "system.stereo_frontend",
    "video_timing": "video.video_timing",
    "tmds_encoder": "video.tmds_encoder",
    "tmds_serializer": "video.tmds_serializer",
    "uart_rx": "serial.uart_rx",
    "uart_tx": "serial.uart_tx",
    "uart_bridge": "serial.uart_bridge",
    "pair_display": "video.pair_display",
    "board_regs": "boards.board_regs",
    "ulx3s": "boards.ulx3s",
    # port bundles
    "ImageStream": "interfaces.stream",
    "QueuePort": "interfaces.queue",
    "FetchPort": "interfaces.fetch_port",
    "CoordPair": "interfaces.coord_pair",
    "CameraBus": "interfaces.camera_bus",
    "AxiLite": "interfaces.axil",
    "AxiStream": "interfaces.axis",
    "DescriptorPort": "interfaces.descriptor",
    "ByteStream": "serial.uart_rx",
    "SramPins": "interfaces.sram_bus",
    "SramCmd": "interfaces.sram_bus",
    "SramRsp": "interfaces.sram_bus",
    "HostPort": "interfaces.sram_bus",
    "StatPort": "interfaces.sram_bus",
    "FrameControl": "memory.frame_buffers",
    "RegisterPorts": "system.register_bank",
}

__all__ = sorted(_EXPORTS)


def __getattr__(name: str):
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    import importlib

    value = getattr(importlib.import_module(f"{__name__}.{_EXPORTS[name]}"), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
