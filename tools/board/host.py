"""What the host tool does with a board (``eyestereo board ...``), on any bus: the board's status, the Harris
settings, grabbing a rectified pair and its features, the adaptive threshold loop.

Everything here is a coroutine on a bus object with ``read``/``write``/``wait`` (and bursts): the board's serial
link (:class:`~eyestereo.tools.board.serial_bus.SerialBus` on pyserial) from the command line, the same class on
a simulated serial line in the board simulation (``sim/benches/tb_board.py``): the simulation runs this code.

The board's monitor (``pair_display``) takes the newest pair every frame with the front end's buffer handshake;
a host that wants a pair itself first stops it (BOARD_CTRL.display_run = 0), waits until it is idle
(BOARD_STATUS.display_idle), takes the pair and gives the display back its run bit, so the two never hold or
want buffers at the same time.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from eyestereo.tools.board.regmap import BOARD_BASE, BOARD_ID, BOARD_REGMAP
from eyestereo.tools.host_driver import BusError, HostDriver
from eyestereo.tools.models.feature_list import MARKER
from eyestereo.tools.models.match_engine import MARKER as MATCH_MARKER
from eyestereo.tools.models.match_engine import parse_list
from eyestereo.tools.models.sram_arbiter import AddressMap, list_words, match_offset
from eyestereo.tools.regmap import REGMAP

__all__ = ["OffsetBus", "Board", "Pair"]


class OffsetBus:
    """A bus seen from ``base`` on (the board's registers at bus address bit 23)."""

    def __init__(self, bus, base: int):
        self.bus, self.base = bus, int(base)

    async def read(self, address):
        return await self.bus.read(self.base + address)

    async def write(self, address, data, strb=0xF):
        return await self.bus.write(self.base + address, data, strb)

    async def wait(self, clocks):
        await self.bus.wait(clocks)


@dataclass
class Pair:
    """A rectified pair and the features of the same frame, as the host read them."""

    left: np.ndarray
    right: np.ndarray
    features: list[tuple[int, int, int]]  # (x, y, camera)
    overflow: bool
    frame: int  # FRAMES when it was taken
    #: the frame's match list (a board built with the matcher, ``take_pair(matches=True)``): (x, y, disparity,
    #: cost, dy) per match, the left corner's x and y; None when not read
    matches: list[tuple[int, int, int, int, int]] | None = None


class Board:
    """The board's two register maps on one bus: :attr:`fe` (the front end's, :class:`HostDriver` of REGMAP) and
    :attr:`regs` (the board's own, BOARD_REGMAP at :data:`BOARD_BASE`)."""

    def __init__(self, bus):
        self.bus = bus
        self.fe = HostDriver(bus, REGMAP)
        self.regs = HostDriver(OffsetBus(bus, BOARD_BASE), BOARD_REGMAP)

    async def check(self) -> None:
        """Both maps answer with their IDs (ValueError naming what answered instead)."""
        board_id = await self.regs.read("BOARD_ID")
        if board_id != BOARD_ID:
            raise ValueError(f"the board answers BOARD_ID {board_id:#010x}, not {BOARD_ID:#010x}: not an eyestereo "
                             f"board design, or another version")
        await self.fe.check_id()

    async def status(self) -> dict[str, int]:
        """Every status field of both maps, the geometry and the clocks, by name."""
        out: dict[str, int] = {}
        for drv, regs in ((self.regs, BOARD_REGMAP.of_kind("status", "const")), (self.fe, REGMAP.of_kind("status"))):
            for r in regs:
                word = await drv.read(r.name)
                for f in r.fields:
                    out[f.name] = (word >> f.lsb) & ((1 << f.width) - 1)
        out["width"], out["height"] = await self.fe.geometry()
        return out

    async def geometry(self) -> tuple[int, int]:
        return await self.fe.geometry()

    async def set_display(self, run: bool) -> None:
        await self.regs.set(display_run=int(bool(run)))

    async def wait_display_idle(self, *, timeout_clocks: int = 50_000_000, poll_clocks: int = 10_000) -> None:
        waited = 0
        while not await self.regs.get("display_idle"):
            if waited >= timeout_clocks:
                raise TimeoutError(f"the display did not stop within {timeout_clocks} clocks")
            await self.bus.wait(poll_clocks)
            waited += poll_clocks

    async def take_pair(self, *, max_features: int = 1023, matches: bool = False, max_matches: int = 1023,
                        timeout_clocks: int = 100_000_000, poll_clocks: int = 10_000) -> Pair:
        """The newest rectified pair and its feature list (the display stopped meanwhile and restarted after;
        TimeoutError when no pair comes: the cameras stopped, or the front end is not running). ``matches``: the
        board was built with the matcher (``ulx3s(matcher=True)``: its list buffers hold ``max_matches`` matches
        after the features, so they lie elsewhere): the frame's match list is read too (:attr:`Pair.matches`)."""
        run = await self.regs.get("display_run")
        await self.set_display(False)
        try:
            await self.wait_display_idle()
            width, height = await self.geometry()
            amap = AddressMap(width, height, list_words(max_features, max_matches if matches else None),
                              cameras=False)
            await self.fe.set(rect_want=1, feat_want=1)
            waited = 0
            while True:
                st = await self.fe.status()
                if st["rect_held"] and st["feat_held"]:
                    break
                if waited >= timeout_clocks:
                    raise TimeoutError(f"no rectified pair within {timeout_clocks} clocks (FRAMES "
                                       f"{await self.fe.read('FRAMES')}; is the front end running?)")
                await self.bus.wait(poll_clocks)
                waited += poll_clocks
            frame = await self.fe.read("FRAMES")
            words = await self.fe.read_sram_words(amap.rectified(st["rect_buf"]), width * height)
            pix = np.asarray(words, dtype=np.uint16).reshape(height, width)
            feats, overflow = await self._feature_list(amap.features(st["feat_buf"]), max_features)
            found = None
            if matches:
                found = await self._match_list(amap.features(st["feat_buf"]) + match_offset(max_features),
                                               max_matches)
            await self.fe.pulse("rect_release", "feat_release")
            await self.fe.set(rect_want=0, feat_want=0)
        finally:
            await self.set_display(bool(run))
        return Pair(left=(pix & 0xFF).astype(np.uint8), right=(pix >> 8).astype(np.uint8), features=feats,
                    overflow=overflow, frame=frame, matches=found)

    async def _match_list(self, base: int, max_matches: int, *, chunk: int = 63) -> list[tuple[int, int, int, int,
                                                                                           int]]:
        """The match list's matches (x, y, disparity, cost, dy), read ``chunk`` words (whole matches) at a time up
        to its trailer; BusError when the words are not a list."""
        limit = 3 * max_matches + 3
        words: list[int] = []
        while len(words) < limit:
            got = await self.fe.read_sram_words(base + len(words), min(chunk, limit - len(words)))
            for i in range(len(words) - len(words) % 3, len(words) + len(got) - 2, 3):
                trip = (words + got)[i:i + 3]
                if trip[0] == MATCH_MARKER:
                    try:
                        lst = parse_list((words + got)[:i + 3])
                    except ValueError as e:
                        raise BusError(f"the match list at SRAM word {base}: {e}") from None
                    return [(int(x), int(y), int(d), int(c), int(dy)) for (x, y, d, c), dy in
                            zip(lst["matches"], lst["dy"])]
            words += got
        raise BusError(f"no match list trailer within {max_matches} matches at SRAM word {base}")

    async def _feature_list(self, base: int, max_features: int, *, chunk: int = 64) -> tuple[list[tuple[int, int, int]],
                                                                                            bool]:
        """The list's features and overflow flag, read ``chunk`` words at a time up to its trailer (a list is
        usually far shorter than its buffer)."""
        feats: list[tuple[int, int, int]] = []
        limit = 2 * max_features + 2
        words: list[int] = []
        while len(words) < limit:
            words += await self.fe.read_sram_words(base + len(words), min(chunk, limit - len(words)))
            while 2 * len(feats) + 1 < len(words):
                w0, w1 = words[2 * len(feats)], words[2 * len(feats) + 1]
                if w0 == MARKER:
                    count, overflow = w1 & 0x7FFF, bool(w1 >> 15)
                    if count != len(feats) and not overflow:
                        raise BusError(f"the feature list's trailer counts {count}, the list holds {len(feats)}")
                    return feats, overflow
                feats.append((w0 & 0x7FFF, w1, w0 >> 15))
        raise BusError(f"no trailer within {max_features} features at SRAM word {base} (it begins "
                       f"{', '.join(f'{w:#06x}' for w in words[:6])})")

    async def set_harris(self, *, k_left: int | None = None, k_right: int | None = None, thresholds_left=None,
                         thresholds_right=None) -> None:
        """k codes and block thresholds (codes), each checked before anything is written."""
        mode = dict(REGMAP.field("mode")[1].values)[await self.fe.get("mode")]
        await self.fe.configure(mode=mode, continuous=bool(await self.fe.get("continuous")), k_left=k_left,
                                k_right=k_right, thresholds_left=thresholds_left, thresholds_right=thresholds_right)

    async def adapt(self, controllers, *, frames: int, timeout_clocks: int = 100_000_000) -> list[tuple[int, int]]:
        """The adaptive threshold loop (thesis 7.2) for ``frames`` frames: each new frame's per-block counts into
        the two controllers (left, right: ``update(counts) -> codes``, :mod:`eyestereo.tools.matching.adaptive`),
        their codes written as the next thresholds. Returns each frame's (features left, right)."""
        totals = []
        after = await self.fe.read("FRAMES")
        for _ in range(frames):
            after = await self.fe.wait_frame(after=after, timeout_clocks=timeout_clocks)
            left, right = await self.fe.feature_counts()
            totals.append((int(sum(left)), int(sum(right))))
            codes_l = controllers[0].update(np.asarray(left))
            codes_r = controllers[1].update(np.asarray(right))
            await self.fe.write_thresholds("THR_LEFT", [int(c) for c in codes_l])
            await self.fe.write_thresholds("THR_RIGHT", [int(c) for c in codes_r])
        return totals
