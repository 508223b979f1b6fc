"""A monitor in Python: K_T loss on the top joint from the torque balance (docs/monitor-api.md)."""
import math

import armfault


class TorqueRatioMonitor(armfault.Monitor):
    """The torque the sensor explains over the torque the current asks for: 1 when healthy,
    the K_T factor when the motor lost torque. Running sums forget over FORGET_S seconds; the
    alarm (latched) when the deficit 1 - ratio passes DEFICIT, refined whenever the estimate
    moves by REFINE. Publishes the deficit's running maximum, so `armfault tune` can sweep it."""
    DEFICIT, REFINE, FORGET_S, MIN_SPEED_RAD_S, SETTLE_S = 0.2, 0.02, 2.0, 0.05, 1.0
    statistics = [armfault.Statistic("kt_deficit", "kt_degradation", DEFICIT)]

    def __init__(self, robot):
        super().__init__(robot)
        self.j = self.joints - 1  # the top joint (signal arrays are 0-based)
        m = robot["modules"][self.j]
        self.ratio, self.mesh, self.f = m["drive"]["ratio"], m["drive"]["mesh_loss_fraction"], m["friction"]
        self.gain = self.ratio * m["motor"]["kt_Nm_per_A"]  # link torque per ampere, as designed
        self.keep = math.exp(-self.dt_s / self.FORGET_S)
        self.asked2 = self.explained_asked = self.moving_s = 0.0
        self.reported, self.worst = None, -math.inf  # the kt_factor of the last alarm, max deficit

    def step(self, t_s, signals):
        qd = signals.qd_est_rad_s.item(self.j)
        if abs(qd) < self.MIN_SPEED_RAD_S:  # at rest, friction is whatever stiction needs
            return None
        tau, f = signals.tau_sensor_Nm.item(self.j), self.f
        friction = self.ratio * (f["viscous_Nm_s_per_rad"] * qd + math.copysign(
            f["coulomb_Nm"] + f["static_Nm"] * math.exp(-f["stribeck_s2_per_rad2"] * qd * qd), qd))
        explained = tau + math.copysign(self.mesh * abs(tau), qd) + friction
        asked = self.gain * signals.i_cmd_A.item(self.j)
        self.asked2 = self.keep * self.asked2 + asked * asked
        self.explained_asked = self.keep * self.explained_asked + explained * asked
        self.moving_s += self.dt_s
        kt_factor = self.explained_asked / self.asked2
        if self.moving_s < self.SETTLE_S:
            return None
        self.worst = self.values[self.j, 0] = max(self.worst, 1 - kt_factor)
        if self.worst <= self.DEFICIT or (self.reported is not None and 1 - kt_factor <= self.DEFICIT):
            return None
        if self.reported is None or abs(kt_factor - self.reported) > self.REFINE:
            self.reported = kt_factor
            return armfault.Verdict(self.j + 1, "defective", "kt_degradation", "kt_factor", kt_factor, 0.9)
        return None
