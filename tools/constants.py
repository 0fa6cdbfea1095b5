"""The library's shared constants: frame sizes, the threshold grid, NMS sizes, share factors, k's default.

One place for the numbers that several layers need. ``tools`` holds it because every layer may import
``tools`` (``hdl`` blocks, ``sim`` benches, the models and the CLI alike), and nothing here depends on
anything else.

* The cameras' frame (CIF, 352 x 288, thesis 3.1) is the default size of every block and bench.
* :data:`FRAME_MIN` .. :data:`FRAME_MAX` bound every ``width`` / ``height`` parameter (4096 keeps the
  column and row counters at 12 bits).
* The adaptive threshold splits a frame into a :data:`THRESHOLD_BLOCKS` grid of blocks, each with its
  own threshold register (thesis 6.3.5).
* Non-maximum suppression takes windows of :data:`NMS_SIZES` (1 = off); :data:`NMS_DEFAULT` is the
  thesis's 3 x 3.
* The stereo Harris chain time-shares its multipliers over :data:`SHARE_FACTORS` clocks per beat.
* k = :data:`K_DEFAULT` (thesis 6.2.3), as the 8-bit ufix[8,8] port code :data:`K_CODE_DEFAULT`
  (round(0.04 * 256) = 10).
"""

#: The cameras' frame size (CIF): every block's and bench's default.
FRAME_WIDTH, FRAME_HEIGHT = 352, 288

#: The range of every frame size parameter.
FRAME_MIN, FRAME_MAX = 2, 4096

#: Threshold blocks per frame (columns, rows): one 20-bit threshold register each, per camera.
THRESHOLD_BLOCKS = (4, 4)

#: Non-maximum suppression window sizes (1: no suppression) and the default.
NMS_SIZES = (1, 3, 5)
NMS_DEFAULT = 3

#: Clocks per beat the stereo Harris chain may share its multipliers over.
SHARE_FACTORS = (1, 2, 3)

#: The Harris constant k and its ufix[8,8] port code.
K_DEFAULT = 0.04
K_CODE_DEFAULT = 10

__all__ = ["FRAME_WIDTH", "FRAME_HEIGHT", "FRAME_MIN", "FRAME_MAX", "THRESHOLD_BLOCKS", "NMS_SIZES",
           "NMS_DEFAULT", "SHARE_FACTORS", "K_DEFAULT", "K_CODE_DEFAULT", "DENSE_DEFAULTS"]

#: The dense chain's defaults (tuned on Tsukuba, Venus and Motorcycle at 352 x 288, docs/dense.md): the model's
#: (``eyestereo.tools.models.dense_stereo.DEFAULTS``) and the DENSE register's reset values.
DENSE_DEFAULTS = dict(window=5, disparities=64, paths=4, p1=10, p2=30, uniqueness=10, lr_check=True, subpixel=True,
                      median=True)

#: The first word of a match list's trailer (the hardware matcher's, issue 29; ``eyestereo.tools.models.match_engine``
#: declares the list's words): a match's first word never equals it (dy = -8, which no match has). Here, not in the
#: model, so that the host driver (which imports no model) finds a list's end by the same constant.
MATCH_MARKER = 0x8000
