"""A backend process whose DDS discovery announcements reach other participants slowly, calling
one Trigger service: `python -m tests.ros2.slow_announcer SERVICE`, with FASTDDS_DEFAULT_PROFILES_FILE
naming a file that holds SLOW_DISCOVERY.

The profile sends the participant's built-in (discovery) traffic through a flow controller that
takes turns between its announcement writers, a few of a few hundred bytes each per 100 ms. The
process opens READERS subscriptions before its service client, so it has far more readers to
announce than writers: a server that appears late learns of the client's request writer about
0.4 s before its response reader, the asymmetric discovery behind Fast DDS's lost replies
(ros2/ros2#1253), while the client sees the server at once.

Prints "calling" once the client exists, then one JSON line: the reply or the error.
"""

from __future__ import annotations

import json
import sys

READERS = 40

SLOW_DISCOVERY = """<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns="http://www.eprosima.com">
  <profiles>
    <participant profile_name="slow_discovery" is_default_profile="true">
      <rtps>
        <flow_controller_descriptor_list>
          <flow_controller_descriptor>
            <name>slow_discovery</name>
            <scheduler>ROUND_ROBIN</scheduler>
            <max_bytes_per_period>6000</max_bytes_per_period>
            <period_ms>100</period_ms>
          </flow_controller_descriptor>
        </flow_controller_descriptor_list>
        <builtin>
          <flow_controller_name>slow_discovery</flow_controller_name>
        </builtin>
      </rtps>
    </participant>
  </profiles>
</dds>
"""


def main(service: str) -> None:
    from std_msgs.msg import String
    from std_srvs.srv import Trigger

    from agent.robot import CancelToken
    from agent.ros2.config import RosConfig
    from agent.ros2.link import RobotLink, ServiceError

    link = RobotLink(RosConfig(), node_name="nrtrans_test_slow_announcer")
    try:
        node = link._ros.node
        for k in range(READERS):
            node.create_subscription(String, f"/nrtrans_test/idle{k}", lambda _msg: None, 10)
        client = link.client(Trigger, service)
        print("calling", flush=True)
        try:
            reply = link.call(client, service, CancelToken())
        except ServiceError as exc:
            print(json.dumps({"error": str(exc)}), flush=True)
        else:
            print(json.dumps({"success": reply.success, "message": reply.message}), flush=True)
    finally:
        link.close()


if __name__ == "__main__":
    main(sys.argv[1])
