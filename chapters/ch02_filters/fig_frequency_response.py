"""Figure: frequency response of every filter, with Nyquist and the first alias marked."""

import matplotlib.pyplot as plt
import numpy as np

from chapters.common import figure_path, result_path, save_figure


def main():
    data = np.load(result_path(__file__, "responses.npz"))
    omega, labels, curves = data["omega"], data["labels"], data["curves"]
    fig, (lin, log) = plt.subplots(1, 2, figsize=(9, 3.8), layout="tight")
    for label, k in zip(labels, curves, strict=True):
        style = "--" if str(label).startswith("gaussian") else "-"
        lin.plot(omega / np.pi, k, style, label=str(label), lw=1.4)
        log.semilogy(omega / np.pi, np.maximum(np.abs(k), 1e-8), style, lw=1.2)
    for ax in (lin, log):
        ax.axvline(1.0, color="0.4", lw=0.8, ls=":")
        ax.axvline(2.0, color="0.4", lw=0.8, ls=":")
        ax.set_xlabel(r"$\omega / \pi$  (1 = Nyquist, 2 = first alias of DC)")
        ax.set_xlim(0, 4)
    lin.axhline(0.0, color="0.7", lw=0.6)
    lin.set_ylabel(r"$K(\omega)$")
    lin.set_title("Frequency response")
    log.set_ylabel(r"$|K(\omega)|$")
    log.set_ylim(1e-6, 2)
    log.set_title("Magnitude (log): leakage past Nyquist")
    lin.legend(fontsize=8, ncol=2)
    save_figure(fig, figure_path(__file__, "frequency_response.png"))


if __name__ == "__main__":
    main()
