"""A belt with parts of NBINS colours; no physics engine, plain kinematics."""

CAMERA_X = 0.2


class Belt:
    def __init__(self, system, seed):
        import numpy as np

        self.random = np.random.default_rng(seed)
        self.nbins = 3
        self.width = 8
        self.time = 0.0
        self.speed = 0.0
        self.parts = []  # dicts: id, x, colour, bin
        self.next_spawn = 0.0
        self.next_id = 0
        self.arm = {}
        self.binned = {}
        self.lost = 0

    def bind(self, system):
        pass

    def advance(self, time):
        dt = time - self.time
        self.time = time
        for p in self.parts:
            if p["bin"] is None:
                p["x"] += self.speed * dt
        for k, pos in self.arm.items():
            station = 0.4 + 0.3 * k
            for p in self.parts:
                if p["bin"] is None and pos > 0.9 and abs(p["x"] - station) < 0.03:
                    p["bin"] = k
                    self.binned[k] = self.binned.get(k, 0) + 1
        for p in self.parts:
            if p["bin"] is None and p["x"] > 1.6:
                p["bin"] = 0
                self.lost += 1
        self.parts = [p for p in self.parts if p["bin"] is None]
        if time >= self.next_spawn and self.speed > 0:
            self.parts.append(
                {"id": self.next_id, "x": 0.0, "colour": int(self.random.integers(1, self.nbins + 1)), "bin": None}
            )
            self.next_id += 1
            self.next_spawn = time + 1.0

    def frame(self):
        # WIDTH pixels spanning CAMERA_X +- 0.04
        pixels = [0] * self.width
        for p in self.parts:
            for i in range(self.width):
                x = CAMERA_X - 0.04 + 0.01 * i
                if abs(p["x"] - x) < 0.02:
                    pixels[i] = p["colour"]
        return pixels

    def close(self):
        pass


def make(system, seed):
    return Belt(system, seed)
