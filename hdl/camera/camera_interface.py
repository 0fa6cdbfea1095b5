"""Camera interface: camera_stream and async_fifo joined: a camera bus in, whole frames in the system clock out."""

from myhdl import block

from eyestereo.hdl.streaming.async_fifo import async_fifo
from eyestereo.hdl.streaming.async_fifo import DEFAULT_DEPTH, check_depth
from eyestereo.hdl.camera.camera_stream import camera_stream, check_camera, check_camera_params
from eyestereo.hdl.common.checks import check_clock, check_reset, check_signal
from eyestereo.hdl.interfaces.queue import check_queue
from eyestereo.hdl.interfaces.stream import ImageStream
from eyestereo.tools.camera import WORD


@block
def camera_interface(cam, wrst, rclk, rrst, source, dropped, *, width: int = 352, height: int = 288,
                     order: str = "YUYV", vsync_active: int = 1, href_active: int = 1,
                     depth: int = DEFAULT_DEPTH):
    """One camera into the system clock: :func:`~eyestereo.hdl.camera.camera_stream.camera_stream` in the camera's
    clock, then :func:`~eyestereo.hdl.streaming.async_fifo.async_fifo` into ``rclk``.

    What comes out on ``source`` is the camera's frames as 16-bit words (Y in bits 7..0, U/V in 15..8:
    :data:`eyestereo.tools.camera.WORD`), whole: a frame the camera broke, that began before the block
    was listening, or that overflowed the FIFO because the reader stalled too long, never ends with
    ``eof``; if part of it had come out, a reset token ends it (see :mod:`eyestereo.hdl.interfaces.queue`).
    ``dropped`` counts the frames that began on the write side (a word of them reached the FIFO, or was
    lost there) and did not come through: broken by the camera, by an overflow, or by ``wrst``. Frames
    camera_stream never started (no VSYNC seen) or broke before their first word are not counted; a
    frame cut on the read side by ``rrst`` is not counted either (the reader was reset with it).

    Ports:
        cam: :class:`~eyestereo.hdl.interfaces.camera_bus.CameraBus`; ``cam_pclk`` clocks the camera domain.
        wrst: camera-domain synchronous reset, active high (synchronise it to ``cam_pclk``).
        rclk: system (read) clock.
        rrst: system-domain synchronous reset, active high.
        source: :class:`~eyestereo.hdl.interfaces.queue.QueuePort` of 16-bit camera words (``rclk``).
        dropped: 16-bit count of dropped frames (``rclk``).

    Parameters:
        width, height, order, vsync_active, href_active: of camera_stream (the camera's geometry and bus).
        depth: FIFO entries (power of two; default 32 in LUT-RAM, absorbs a reader stall of 3.5 us at the
            OV6630's 9 M words/s; 1024 = one RAMB16, 135 us, with a slower read clock: async_fifo's
            ``DEFAULT_DEPTH``; see docs/camera.md).

    Latency: camera_stream's 1 PCLK, one PCLK into the FIFO, then three ``rclk`` edges (synchroniser and
    block RAM read) when the FIFO is empty and the reader ready.

    Resources: camera_stream plus async_fifo: LUT-RAM at the default depth, one RAMB16 at 1024.
    """
    check_camera("cam", cam)
    check_reset(wrst, "wrst")
    check_clock(rclk, "rclk")
    check_reset(rrst, "rrst")
    check_queue("source", source, width=WORD.width)
    check_signal("dropped", dropped, width=16)
    width, height, order, vsync_active, href_active = check_camera_params(width, height, order, vsync_active,
                                                                          href_active)
    depth = check_depth(depth)
    words = ImageStream(WORD)
    rx = camera_stream(cam, wrst, words, width=width, height=height, order=order, vsync_active=vsync_active,
                       href_active=href_active)
    fifo = async_fifo(cam.pclk, wrst, words, rclk, rrst, source, dropped, depth=depth)
    return rx, fifo


@block
def camera_pair(cam_l, wrst_l, cam_r, wrst_r, rclk, rrst, source_l, source_r, dropped_l, dropped_r, *,
                width: int = 352, height: int = 288, order: str = "YUYV", vsync_active: int = 1,
                href_active: int = 1, depth: int = DEFAULT_DEPTH):
    """Two cameras, each with its own clock and reset, into one system clock: two
    :func:`camera_interface` blocks side by side (the thesis's stereo rig, Fig. 7.2).

    Ports: ``cam_l``/``cam_r``, ``wrst_l``/``wrst_r`` (each camera's domain), ``rclk``, ``rrst``,
    ``source_l``/``source_r`` (queue read ports), ``dropped_l``/``dropped_r``. Parameters, latency: as
    :func:`camera_interface`, the same for both cameras. Resources: twice camera_interface.
    """
    for side, cam, wrst, source, dropped in (("l", cam_l, wrst_l, source_l, dropped_l),
                                             ("r", cam_r, wrst_r, source_r, dropped_r)):
        check_camera(f"cam_{side}", cam)
        check_reset(wrst, f"wrst_{side}")
        check_queue(f"source_{side}", source, width=WORD.width)
        check_signal(f"dropped_{side}", dropped, width=16)
    check_clock(rclk, "rclk")
    check_reset(rrst, "rrst")
    width, height, order, vsync_active, href_active = check_camera_params(width, height, order, vsync_active,
                                                                          href_active)
    depth = check_depth(depth)
    left = camera_interface(cam_l, wrst_l, rclk, rrst, source_l, dropped_l, width=width, height=height,
                            order=order, vsync_active=vsync_active, href_active=href_active, depth=depth)
    right = camera_interface(cam_r, wrst_r, rclk, rrst, source_r, dropped_r, width=width, height=height,
                             order=order, vsync_active=vsync_active, href_active=href_active, depth=depth)
    return left, right
