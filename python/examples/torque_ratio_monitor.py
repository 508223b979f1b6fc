"""A monitor in Python: K_T loss on the top joint from the torque balance (docs/monitor-api.md)."""
import math

import armfault


class TorqueRatioMonitor(armfault.Monitor):
    """The torque the sensor explains over the torque the current asks for: 1 when healthy,
    the K_T factor when the motor lost torque. Running sums forget over FORGET_S seconds; an
    alarm below THRESHOLD, refined whenever the estimate moves by REFINE."""
    THRESHOLD, REFINE, FORGET_S, MIN_SPEED_RAD_S, SETTLE_S = 0.8, 0.02, 2.0, 0.05, 1.0

    def __init__(self, robot):
        super().__init__(robot)
        self.j = self.joints - 1  # the top joint (signal arrays are 0-based)
        m = robot["modules"][self.j]
        self.ratio, self.mesh, self.f = m["drive"]["ratio"], m["drive"]["mesh_loss_fraction"], m["friction"]
        self.gain = self.ratio * m["motor"]["kt_Nm_per_A"]  # link torque per ampere, as designed
        self.keep = math.exp(-self.dt_s / self.FORGET_S)
        self.asked2 = self.explained_asked = self.moving_s = 0.0
        self.reported = None  # the kt_factor of the last alarm

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
        if self.moving_s < self.SETTLE_S or kt_factor > self.THRESHOLD:
            return None
        if self.reported is None or abs(kt_factor - self.reported) > self.REFINE:
            self.reported = kt_factor
            return armfault.Verdict(self.j + 1, "defective", "kt_degradation", "kt_factor", kt_factor, 0.9)
        return None
