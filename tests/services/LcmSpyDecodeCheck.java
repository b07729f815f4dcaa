// Decodes every message of an lcm-log the way lcm-spy does: the type is found by its fingerprint
// among the classes on the class path (LCMTypeDatabase) and built from the bytes. Prints a count
// per channel and type, and of the messages that have no type or do not decode; exits 1 if
// nothing decoded.
import java.io.ByteArrayInputStream;
import java.io.DataInput;
import java.io.DataInputStream;
import java.io.EOFException;
import java.util.Map;
import java.util.TreeMap;
import lcm.logging.Log;
import lcm.spy.LCMTypeDatabase;

public class LcmSpyDecodeCheck {
    public static void main(String[] args) throws Exception {
        Log log = new Log(args[0], "r");
        LCMTypeDatabase types = new LCMTypeDatabase();
        Map<String, Integer> decoded = new TreeMap<>();
        while (true) {
            Log.Event event;
            try {
                event = log.readNext();
            } catch (EOFException end) {
                break;
            }
            String result;
            try {
                long fingerprint = new DataInputStream(new ByteArrayInputStream(event.data)).readLong();
                Class<?> type = types.getClassByFingerprint(fingerprint);
                if (type == null) {
                    result = "no-type";
                } else {
                    type.getConstructor(DataInput.class).newInstance(new DataInputStream(new ByteArrayInputStream(event.data)));
                    result = type.getName();
                }
            } catch (Exception undecodable) {
                result = "undecodable";
            }
            decoded.merge(event.channel + " " + result, 1, Integer::sum);
        }
        decoded.forEach((key, count) -> System.out.println(key + " " + count));
        System.exit(decoded.keySet().stream().anyMatch(key -> key.contains(" evldt.")) ? 0 : 1);
    }
}
