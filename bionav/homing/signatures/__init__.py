"""Image parameter signatures (thesis section 3.5) as plain functions on arrays.

Each module holds one family of the thesis' image parameters, computed on a
canonical unfolded panorama (:mod:`bionav.geometry`) of shape ``(H, W)``:

* :mod:`~bionav.homing.signatures.rings` -- ring segmentation (concentric rings
  of the raw mirror image = equal row bands of the unfolded image),
* :mod:`~bionav.homing.signatures.statistics` -- [mean] [std] [skew] [kurt],
* :mod:`~bionav.homing.signatures.histogram` -- [hist] [ent],
* :mod:`~bionav.homing.signatures.cog` -- [cog] [cog_l],
* :mod:`~bionav.homing.signatures.fourier` -- row-wise and profile DFTs for
  [fc] [mean_fft] [std_fft] [cog_fft], their amplitude versions and
  [mffc_phase] [mffc_abs].

The ``bionav.signatures`` plugins (:mod:`bionav.plugins.signatures`) wrap these
functions into signature vectors for :class:`bionav.plugins.homing.parameter.ParameterHoming`.
"""
