"""Unloads and loads one UAV's FormationPlanner nodelet in a running simulation.launch, as a crashed
or reloaded nodelet (test/ros/planner_restart.sh, leader_restart.sh): its private parameters stay on
the parameter server; loaded again into /uav<i>/manager with the remaps of launch/sim_uav.launch."""
import os
import re
import signal
import subprocess

REMAPS = ["odometry_in:=odometry", "worker_state_in:=worker_state", "plans_in:=lcm/plans",
          "wind_estimate_in:=wind_estimation", "plan_out:=plan", "formation_params_in:=formation_params",
          "formation_params_out:=formation_params", "formation_command_in:=formation_command",
          "leadership_state_in:=leadership_state", "abort_in:=abort", "abort_state_out:=abort_state",
          "command_ack_out:=command_ack", "assistance_in:=assistance", "assistance_state_out:=assistance_state"]


def unload(ns):
    """SIGINT to the loader of <ns>/formation_planner (it unloads the nodelet); the rosnode info text on failure."""
    info = subprocess.run(["rosnode", "info", ns + "/formation_planner"], capture_output=True, text=True).stdout
    pid = re.search(r"Pid: (\d+)", info)
    if not pid:
        return info
    os.kill(int(pid.group(1)), signal.SIGINT)
    return None


def load(ns, log_path):
    """Loads <ns>/formation_planner again into <ns>/manager; the loader's output goes to log_path."""
    loader = open(log_path, "w")
    subprocess.Popen(["rosrun", "nodelet", "nodelet", "load", "gesture_formation/FormationPlanner", "manager",
                      "__name:=formation_planner"] + REMAPS, env=dict(os.environ, ROS_NAMESPACE=ns),
                     stdout=loader, stderr=subprocess.STDOUT)
