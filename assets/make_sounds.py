"""Synthesise the game's sounds into small WAV files beside this script.

    python assets/make_sounds.py

Mono, 16-bit, 22050 Hz, made from sine tones with short attack and release ramps (so they do not
click) and a gentle exponential decay. Deterministic: the same files on every run. The window plays
them only when pygame's mixer opens; see ``armgame/ui/sound.py``.
"""

from __future__ import annotations

import wave
from pathlib import Path

import numpy as np

RATE = 22050
HERE = Path(__file__).resolve().parent


def tone(freqs: tuple[float, float], seconds: float, decay: float = 8.0, volume: float = 0.5,
         harmonics: tuple[float, ...] = (1.0, 0.3)) -> np.ndarray:
    """A tone gliding from ``freqs[0]`` to ``freqs[1]`` Hz, with a little of its octave for body."""
    n = round(seconds * RATE)
    t = np.arange(n) / RATE
    freq = np.linspace(freqs[0], freqs[1], n)
    phase = 2 * np.pi * np.cumsum(freq) / RATE
    wave_ = sum(a * np.sin((k + 1) * phase) for k, a in enumerate(harmonics))
    envelope = np.exp(-decay * t)
    ramp = min(n // 2, round(0.004 * RATE))
    envelope[:ramp] *= np.linspace(0.0, 1.0, ramp)
    envelope[-ramp:] *= np.linspace(1.0, 0.0, ramp)
    return volume * wave_ / sum(harmonics) * envelope


def silence(seconds: float) -> np.ndarray:
    return np.zeros(round(seconds * RATE))


SOUNDS = {
    "hit": lambda: np.concatenate([tone((880, 880), 0.06, 10), tone((1320, 1320), 0.14, 14)]),
    "reset": lambda: tone((260, 130), 0.18, 10, 0.6),
    "tick": lambda: tone((660, 660), 0.09, 20, 0.45),
    "go": lambda: tone((990, 990), 0.22, 8, 0.5),
    "end": lambda: np.concatenate([tone((784, 784), 0.16, 6), silence(0.03), tone((659, 659), 0.16, 6),
                                    silence(0.03), tone((523, 523), 0.35, 5)]),
}


def write_wav(path: Path, samples: np.ndarray) -> None:
    data = (np.clip(samples, -1.0, 1.0) * 32767).astype("<i2").tobytes()
    with wave.open(str(path), "wb") as f:
        f.setnchannels(1)
        f.setsampwidth(2)
        f.setframerate(RATE)
        f.writeframes(data)


def main(folder: Path = HERE) -> list[Path]:
    paths = []
    for name, make in SOUNDS.items():
        path = folder / f"{name}.wav"
        write_wav(path, make())
        paths.append(path)
    return paths


if __name__ == "__main__":
    for p in main():
        print(f"wrote {p} ({p.stat().st_size} bytes)")
